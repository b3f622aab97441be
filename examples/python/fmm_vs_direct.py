#!/usr/bin/env python3
"""The FMM against the direct sum: error and time per tolerance, Stokeslets on a sphere.

    PYTHONPATH=build/python python3 examples/python/fmm_vs_direct.py [--n 20000] [--plot fmm_vs_direct.png]

Prints one line per tolerance: the order the FMM chose, its relative L2 error against the direct
sum (at most the tolerance: the FMM's contract) and both times; with --plot, draws error and time
against the tolerance.
"""
import argparse
import time

import numpy as np

import capsflow


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=20000, help="points on the unit sphere (sources = targets)")
    ap.add_argument("--plot", help="write a figure to this file")
    a = ap.parse_args()

    rng = np.random.default_rng(1)
    points = rng.normal(size=(a.n, 3))
    points /= np.linalg.norm(points, axis=1, keepdims=True)
    forces = rng.normal(size=(a.n, 3))

    t0 = time.perf_counter()
    exact = capsflow.fmm.stokeslet_direct(points, forces)
    direct_s = time.perf_counter() - t0
    print(f"direct sum: {a.n} points, {direct_s:.3f} s")

    rows = []
    for tol in (1e-3, 1e-6, 1e-8):
        capsflow.fmm.stokeslet(points[:10], forces[:10], tolerance=tol)  # operators loaded (or built) once
        t0 = time.perf_counter()
        u = capsflow.fmm.stokeslet(points, forces, tolerance=tol)
        fmm_s = time.perf_counter() - t0
        err = np.linalg.norm(u - exact) / np.linalg.norm(exact)
        rows.append((tol, err, fmm_s))
        print(f"tolerance {tol:.0e}: order {capsflow.fmm.order_for_tolerance(tol):2d}, "
              f"relative L2 error {err:.2e}, {fmm_s:.3f} s ({direct_s / fmm_s:.1f}x faster than direct)")

    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        tol, err, secs = map(np.array, zip(*rows))
        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.5))
        ax1.loglog(tol, err, "o-", label="FMM")
        ax1.loglog(tol, tol, "k--", label="error = tolerance")
        ax1.set_xlabel("tolerance")
        ax1.set_ylabel("relative L2 error")
        ax1.legend()
        ax2.semilogx(tol, secs, "o-", label="FMM")
        ax2.axhline(direct_s, color="k", ls="--", label="direct")
        ax2.set_xlabel("tolerance")
        ax2.set_ylabel("seconds")
        ax2.legend()
        fig.suptitle(f"Stokeslets on a sphere, N = {a.n}")
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)
        print(f"figure: {a.plot}")


if __name__ == "__main__":
    main()
