#!/usr/bin/env python3
"""A capsule's axial profile over time in a tube: its cross-section in the x1-x2 plane (the plane of
the axis) at every output, drawn inside the tube's wall.

    PYTHONPATH=build/python python3 examples/python/channel_profile.py [--level 2] [--t-end 1]
        [--out capsule_in_tube] [--plot channel_profile.png] [--run FOLDER]

Runs scenes/capsule_in_tube.toml (a Skalak capsule at confinement 0.9 in Poiseuille's flow,
docs/channel.md §5) with mesh.level and time.t_end changed into OUT, or reads the run folder given
by --run, then draws the profiles from run.h5 (/profiles/<k>/x1x2: the polylines of the
cross-section, in the frame that moves with the capsule, docs/scene-and-output.md §3.2), coloured
by time, with the wall at x2 = ±radius; it prints U/V and the rear's curvature at the end.
"""
import argparse
import sys
from pathlib import Path

import h5py
import matplotlib.pyplot as plt
import numpy as np

import capsflow

SCENE = Path(__file__).resolve().parents[2] / "scenes" / "capsule_in_tube.toml"


def profiles(run_h5: Path):
    """(time, list of polylines as arrays of (x1, x2)) for every output."""
    out = []
    with h5py.File(run_h5, "r") as f:
        for name in sorted(f["profiles"]):
            g = f["profiles"][name]
            points, offsets = g["x1x2"]["points"][()], g["x1x2"]["offsets"][()]
            lines = [points[offsets[i]:offsets[i + 1], :2] for i in range(len(offsets) - 1)]
            out.append((float(g.attrs["time"]), lines))
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--level", type=int, default=2, help="mesh level (2: 320 elements)")
    ap.add_argument("--t-end", type=float, default=1.0, help="t at the end, in ℓ/V")
    ap.add_argument("--out", default="capsule_in_tube", help="folder of the run")
    ap.add_argument("--run", default=None, help="draw this run folder instead of running")
    ap.add_argument("--plot", default="channel_profile.png", help="the figure")
    ap.add_argument("--threads", type=int, default=None)
    a = ap.parse_args()

    if a.run is None:
        scene = capsflow.Scene(SCENE).set("mesh.level", a.level).set("time.t_end", a.t_end)
        capsflow.run(scene, a.out, overwrite=True, threads=a.threads, log=False)
        folder = Path(a.out)
    else:
        folder = Path(a.run)
    run = capsflow.read_run(folder)
    radius = run.summary["channel"]["radius"]
    shapes = profiles(folder / "run.h5")
    fig, ax = plt.subplots(figsize=(7, 3.6))
    times = [t for t, _ in shapes]
    norm = plt.Normalize(min(times), max(times) if max(times) > min(times) else min(times) + 1)
    for t, lines in shapes:
        for line in lines:
            ax.plot(line[:, 0], line[:, 1], color=plt.cm.viridis(norm(t)), lw=1)
    for y in (-radius, radius):
        ax.axhline(y, color="0.3", lw=2)
    ax.set_ylim(-1.15 * radius, 1.15 * radius)
    ax.set_aspect("equal")
    ax.set_xlabel("x1 / ℓ (frame moving with the capsule; flow →)")
    ax.set_ylabel("x2 / ℓ")
    fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap="viridis"), ax=ax, label="t (ℓ/V)")
    fig.tight_layout()
    fig.savefig(a.plot, dpi=150)
    print(f"U/V {run.summary['velocity_ratio']:.4f}  rear curvature {run.summary.get('rear_curvature', float('nan')):.3f}  "
          f"outputs {len(shapes)}  figure {a.plot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
