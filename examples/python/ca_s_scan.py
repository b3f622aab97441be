#!/usr/bin/env python3
"""A scan over the capillary number: the steady deformation D12 of a capsule in simple shear
against Ca_s, with first-order small-deformation theory.

    PYTHONPATH=build/python python3 examples/python/ca_s_scan.py [--ca 0.025,0.05,0.1,0.2]
        [--level 2] [--t-end 4] [--out ca_s_scan] [--plot ca_s_scan.png]

Each Ca_s is one run of scenes/sphere_simple_shear.toml (an initially spherical capsule with a
neo-Hookean membrane in simple shear v = x2 e1) with mesh.level and time.t_end changed, into
OUT/ca_s=<value>/ (a run folder: it opens in ParaView and restarts with the command line). The
script prints one line per run and draws D12 at the end of each run against Ca_s, with the
small-deformation line D = (25/12) Ca_s of a neo-Hookean membrane (Barthès-Biesel 1980,
docs/small-deformation.md), which the runs follow at small Ca_s and leave as Ca_s grows.
The defaults (320 elements, γ̇t = 4) take seconds per run; use --level 3 --t-end 10 for the
figure's shape.
"""
import argparse
import sys
from pathlib import Path

import capsflow

SCENE = Path(__file__).resolve().parents[2] / "scenes" / "sphere_simple_shear.toml"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ca", default="0.025,0.05,0.1,0.2", help="the Ca_s values, comma-separated")
    ap.add_argument("--level", type=int, default=2, help="mesh level (2: 320 elements)")
    ap.add_argument("--t-end", type=float, default=4.0, help="γ̇t at the end of each run")
    ap.add_argument("--out", default="ca_s_scan", help="folder of the runs")
    ap.add_argument("--plot", default="ca_s_scan.png", help="the figure")
    ap.add_argument("--threads", type=int, default=None)
    a = ap.parse_args()
    ca_values = [float(c) for c in a.ca.split(",")]

    d12 = []
    for ca in ca_values:
        scene = capsflow.Scene(SCENE).set("mesh.level", a.level).set("time.t_end", a.t_end).set("flow.ca_s", ca)
        result = capsflow.run(scene, Path(a.out) / f"ca_s={ca:g}", overwrite=True, threads=a.threads, log=False)
        s = result.summary
        d12.append(s["D12"])
        print(f"Ca_s {ca:<6g} D12 {s['D12']:.4f}  (25/12 Ca_s = {25 / 12 * ca:.4f})  t {s['t']:g}  "
              f"{s['stop_reason']}  {s['steps']} steps")

    import matplotlib
    matplotlib.use("Agg")  # a file, no display needed
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 3.6))
    ax.plot(ca_values, d12, "o-", label=f"capsflow, {s['elements']} elements, γ̇t = {a.t_end:g}")
    top = max(ca_values)
    ax.plot([0, top], [0, 25 / 12 * top], "--", color="grey", label="small deformation: 25/12 Ca_s")
    ax.set_xlabel("Ca_s")
    ax.set_ylabel("D12")
    ax.set_title("neo-Hookean capsule in simple shear")
    ax.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(a.plot, dpi=120)
    print(f"figure: {a.plot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
