#!/usr/bin/env python3
"""A capsule's passage through the constricted duct against Park & Dimitrakopoulos (2013).

    python3 perf/channel/constriction_vs_park.py RUN_FOLDER [--plot FILE.png]

RUN_FOLDER is a `capsflow run scenes/capsule_in_constriction.toml` (any mesh level; finished or not). From
its run.h5 (node positions at every output) this takes the capsule's volume centroid and its
extents along x1 (axial), x2 (the narrowed direction) and x3, in the units of the digitised data
(perf/channel/data/park2013_constriction.csv: x_c/H_c from the narrow part's middle, l/(2a) with a
the capsule's radius at rest), interpolates them at the data's positions, and prints each extent's
largest and RMS difference over the data points the run reached (docs/channel.md §5).
"""
import argparse
import csv
import json
from pathlib import Path

import h5py
import numpy as np

DATA = Path(__file__).resolve().parent / "data" / "park2013_constriction.csv"
EXTENTS = {"axial": 0, "narrowed": 1, "across": 2}  # the data's names → the run's axis


def volume_centroid(x, tri):
    a, b, c = x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]]
    v = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    return ((a + b + c) / 4.0 * v[:, None]).sum(axis=0) / v.sum()


def run_curves(folder):
    with h5py.File(folder / "run.h5", "r") as f:
        channel = json.loads(f["metadata/scene_resolved"][()])["channel"]
        radius = channel["radius"]
        center, height = channel["constriction_center"] * radius, channel["constriction_height"] * radius
        tri = f["mesh/triangles"][()]
        x0 = f["mesh/reference_positions"][()]
        # the capsule's radius at rest: the mesh's sphere of the same volume
        a = np.cbrt(3 * np.abs(np.einsum("ij,ij->i", x0[tri[:, 0]], np.cross(x0[tri[:, 1]], x0[tri[:, 2]]))).sum() / 6 / (4 * np.pi))
        rows = []
        for name in sorted(f["steps"].keys()):
            x = f["steps"][name]["positions"][()]
            c = volume_centroid(x, tri)
            rows.append([(c[0] - center) / height] + list((x.max(axis=0) - x.min(axis=0)) / (2 * a)))
    return np.array(rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run", type=Path)
    ap.add_argument("--plot", type=Path)
    args = ap.parse_args()
    ours = run_curves(args.run)
    data = {}
    with open(DATA) as f:
        for row in csv.reader(line for line in f if not line.startswith("#")):
            if row[0] == "extent":
                continue
            data.setdefault(row[0], []).append((float(row[1]), float(row[2])))
    print(f"run: {args.run}  x_c/H_c from {ours[0, 0]:.2f} to {ours[-1, 0]:.2f}")
    print("| extent | data points reached | largest difference | RMS difference | where largest (x_c/H_c) |")
    print("|---|---:|---:|---:|---:|")
    for name, axis in EXTENTS.items():
        pts = np.array(sorted(data[name]))
        reach = (pts[:, 0] >= ours[0, 0]) & (pts[:, 0] <= ours[-1, 0])
        ref = pts[reach]
        mine = np.interp(ref[:, 0], ours[:, 0], ours[:, 1 + axis])
        diff = mine - ref[:, 1]
        k = int(np.argmax(np.abs(diff)))
        print(f"| {name} | {reach.sum()} of {len(pts)} | {diff[k]:+.3f} | {np.sqrt(np.mean(diff ** 2)):.3f} | {ref[k, 0]:.2f} |")
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4))
        for name, axis in EXTENTS.items():
            pts = np.array(sorted(data[name]))
            line, = ax.plot(ours[:, 0], ours[:, 1 + axis], label=f"capsflow {name}")
            ax.plot(pts[:, 0], pts[:, 1], "o", mfc="none", color=line.get_color(), label=f"Park & Dimitrakopoulos {name}")
        ax.set_xlabel("x_c / H_c")
        ax.set_ylabel("l / 2a")
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)


if __name__ == "__main__":
    main()
