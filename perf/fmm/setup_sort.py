#!/usr/bin/env python3
"""Seconds per FMM set-up (tree, sort and lists: Fmm::setup through capsflow.fmm's move()) for the
boundary integral's shape at 81 920 elements: 122 880 sources and 40 962 targets on the unit sphere,
p = 8 (tolerance 2.5e-6), 2 threads; the median of 5 rounds of 40 set-ups. Run alone on the machine.

  /usr/bin/python3 perf/fmm/setup_sort.py [--module-dir build/python]
"""
import argparse
import os
import statistics
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--module-dir", default=os.path.join(ROOT, "build", "python"))
    a = ap.parse_args()
    sys.path.insert(0, a.module_dir)
    import numpy as np
    import capsflow.fmm as fmm
    rng = np.random.default_rng(1)

    def sphere(n):
        x = rng.normal(size=(n, 3))
        return x / np.linalg.norm(x, axis=1)[:, None]

    src, trg = sphere(122880), sphere(40962)
    o = fmm.StokesletFmm(src, trg, tolerance=2.5e-6, threads=2)
    rounds = []
    for _ in range(5):
        t = time.perf_counter()
        for _ in range(40):
            o.move(src, trg)
        rounds.append((time.perf_counter() - t) / 40)
    print(f"set-up: median {statistics.median(rounds) * 1e3:.2f} ms (rounds: "
          + ", ".join(f"{r * 1e3:.2f}" for r in rounds) + f"), order {o.order}")


if __name__ == "__main__":
    main()
