#!/usr/bin/python3
"""Turn a capsflow output folder into PNG figures (the paper's Fig. 4, 5, 12 and Table 1 style).

    python3 scripts/plot_run.py OUTDIR [--times 0 1 2 5] [--out OUTDIR/figures]

Writes into the figures folder:
  taylor.png          D12, D13, D23 against t (timeseries.csv)
  profiles_x1x3.png   mid-surface profiles in the flow plane x1x3 at the chosen times (run.h5)
  profiles_x2x3.png   ... in the cross plane x2x3
  energy_ratio.png    histogram of the nodal bending/membrane energy ratio E_b/E_m at the last
                      step (when the run stored the "energy" fields), with its statistics printed
Needs python3-matplotlib, python3-numpy and python3-h5py (Debian packages; setup.sh installs them).
"""
import argparse
import csv
import json
import os
import sys

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    # An empty field is a value not defined yet (e.g. steady_measure in the first time unit).
    return {k: np.array([float(r[k]) if r[k] != "" else np.nan for r in rows]) for k in rows[0]} if rows else {}


def nearest_steps(h5, times):
    keys = sorted(h5["profiles"].keys())
    t = np.array([h5["profiles"][k].attrs["time"] for k in keys])
    return [(keys[int(np.argmin(abs(t - want)))], float(t[int(np.argmin(abs(t - want)))])) for want in times]


def plot_profiles(h5, plane, times, path):
    axes = {"x1x3": (0, 2, "$x_1$", "$x_3$"), "x2x3": (1, 2, "$x_2$", "$x_3$"), "x1x2": (0, 1, "$x_1$", "$x_2$")}[plane]
    fig, ax = plt.subplots(figsize=(5, 5))
    for key, t in nearest_steps(h5, times):
        g = h5["profiles"][key][plane]
        pts, off = g["points"][()], g["offsets"][()]
        for a, b in zip(off[:-1], off[1:]):
            ax.plot(pts[a:b, axes[0]], pts[a:b, axes[1]], label=f"$\\dot\\gamma t$ = {t:g}" if a == 0 else None)
    ax.set_aspect("equal")
    ax.set_xlabel(axes[2])
    ax.set_ylabel(axes[3])
    ax.set_title(f"mid-surface profile, {plane} plane")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("outdir")
    p.add_argument("--times", type=float, nargs="*", default=None, help="profile times (default: 5 evenly spaced)")
    p.add_argument("--out", default=None, help="figures folder (default OUTDIR/figures)")
    a = p.parse_args()
    figs = a.out or os.path.join(a.outdir, "figures")
    os.makedirs(figs, exist_ok=True)

    ts = read_csv(os.path.join(a.outdir, "timeseries.csv"))
    fig, ax = plt.subplots(figsize=(6, 4))
    for k in ("D12", "D13", "D23"):
        ax.plot(ts["t"], ts[k], label=k)
    ax.set_xlabel(r"$\dot\gamma t$")
    ax.set_ylabel("Taylor deformation")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(figs, "taylor.png"), dpi=150)
    plt.close(fig)

    try:
        import h5py
    except ImportError:
        sys.exit("plot_run.py: python3-h5py is needed for profiles and energy maps (apt-get install python3-h5py)")
    with h5py.File(os.path.join(a.outdir, "run.h5"), "r") as h5:
        times = a.times if a.times else list(np.linspace(ts["t"][0], ts["t"][-1], 5))
        for plane in ("x1x3", "x2x3"):
            plot_profiles(h5, plane, times, os.path.join(figs, f"profiles_{plane}.png"))
        last = sorted(h5["steps"].keys())[-1]
        step = h5["steps"][last]
        if "E_bending" in step and "E_membrane" in step:
            eb, em = step["E_bending"][()], step["E_membrane"][()]
            ratio = eb / np.maximum(em, 1e-300)
            stats = {"t": float(step.attrs["time"]), "max": float(ratio.max()), "median": float(np.median(ratio)),
                     "p90": float(np.percentile(ratio, 90)), "fraction_above_0.2": float(np.mean(ratio > 0.2))}
            if "E_shear" in step:
                stats["max_shear_over_membrane"] = float((step["E_shear"][()] / np.maximum(em, 1e-300)).max())
            fig, ax = plt.subplots(figsize=(6, 4))
            ax.hist(np.log10(np.maximum(ratio, 1e-12)), bins=60)
            ax.set_xlabel(r"$\log_{10}(E_b/E_m)$ per node")
            ax.set_ylabel("nodes")
            ax.set_title(f"bending / membrane energy ratio at $\\dot\\gamma t$ = {stats['t']:g}")
            fig.tight_layout()
            fig.savefig(os.path.join(figs, "energy_ratio.png"), dpi=150)
            plt.close(fig)
            print(json.dumps({"energy_ratio": stats}))
    print(f"figures in {figs}")


if __name__ == "__main__":
    main()
