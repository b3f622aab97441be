#!/usr/bin/env python3
"""Stokes reversibility of a capsule pair in simple shear (docs/several-capsules.md).

For two rigid spheres the relative trajectory is symmetric under x1 -> -x1 (Batchelor & Green
1972): where the separation along the flow is the mirror image of the start, dx(t*) = -dx(0), the
cross-stream separation is the one they started with, dy(t*) = dy(0). A deformable pair breaks
the symmetry; a nearly rigid one must keep it to within its deformability. Reads the timeseries.csv
of runs of two capsules (capsflow run with [layout] count = 2) and prints dy(0), t*, dy(t*) (linear
interpolation between rows) and dy at the end.

    perf/suspension/mirror_offset.py RUN_FOLDER...
"""
import csv
import sys

import numpy as np


def mirror_offset(folder):
    with open(f"{folder}/timeseries.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(r["t"]) for r in rows])
    dx = np.array([float(r["c2.centroid1"]) - float(r["c1.centroid1"]) for r in rows])
    dy = np.array([float(r["c2.centroid2"]) - float(r["c1.centroid2"]) for r in rows])
    after = np.nonzero((dx + dx[0]) * np.sign(-dx[0]) >= 0)[0]  # rows at or past the mirror point
    after = after[after > 0]
    if len(after) == 0:
        return dy[0], None, None, dy[-1]
    k = after[0]
    w = (-dx[0] - dx[k - 1]) / (dx[k] - dx[k - 1])
    return dy[0], t[k - 1] + w * (t[k] - t[k - 1]), dy[k - 1] + w * (dy[k] - dy[k - 1]), dy[-1]


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    print(f"{'run':<40} {'dy(0)':>8} {'t*':>7} {'dy(t*)':>9} {'dy(t*)-dy(0)':>13} {'dy(end)':>8}")
    for folder in sys.argv[1:]:
        dy0, ts, dys, dyend = mirror_offset(folder)
        if ts is None:
            print(f"{folder:<40} {dy0:8.4f}  (the run ends before the mirror point)")
        else:
            print(f"{folder:<40} {dy0:8.4f} {ts:7.3f} {dys:9.5f} {dys - dy0:13.2e} {dyend:8.5f}")
