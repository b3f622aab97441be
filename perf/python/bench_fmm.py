#!/usr/bin/env python3
"""capsflow.fmm.stokeslet against the C++ benchmark on the same points (floor: within 5 %, perf/RESULTS.md §1.7).

    PYTHONPATH=BUILD/python python3 perf/python/bench_fmm.py --build BUILD [--n 1e5] [--tol 1e-6]
        [--threads 2] [--reps 5] [--dist sphere]

BUILD is configured with -DCAPSFLOW_NATIVE=ON -DCAPSFLOW_BENCHMARKS=ON (targets capsflow_python and
fmm_bench built). The points and forces are written to a file that fmm_bench reads (--input), so
both time the same sum; both use OMP_WAIT_POLICY=passive and the same threads, and the operators
are loaded before timing. C++: fmm_bench's median setup + median evaluation. Python: the median of
whole stokeslet() calls (argument checks, tree, evaluation, output array). Prints one JSON line.
Also reports the traced memory of one call over its output's size (1.0: no input was copied).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

os.environ.setdefault("OMP_WAIT_POLICY", "passive")
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "python"))
from points import forces, make_points  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", required=True, type=Path)
    ap.add_argument("--n", type=float, default=1e5)
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--dist", default="sphere", choices=["sphere", "cube", "clustered"])
    a = ap.parse_args()
    os.environ.setdefault("CAPSFLOW_CACHE_DIR", str(a.build / "fmm-cache"))
    import capsflow  # after CAPSFLOW_CACHE_DIR: the operators are read from there

    n = int(a.n)
    src, f = make_points(a.dist, n, 1), forces(n, 2)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "points.txt"
        with open(path, "w") as out:
            out.write(f"{n} 0\n")
            np.savetxt(out, np.hstack([src, f]), fmt="%.17g")
        bench = subprocess.run([str(a.build / "perf" / "fmm" / "fmm_bench"), "--input", str(path), "--tol", str(a.tol),
                                "--threads", str(a.threads), "--reps", str(a.reps)],
                               capture_output=True, text=True, check=True)
    cpp = json.loads(bench.stdout.strip().splitlines()[-1])
    cpp_s = cpp["setup_s"] + cpp["eval_s"]

    capsflow.fmm.stokeslet(src, f, tolerance=a.tol, threads=a.threads)  # loads the operators
    times = []
    for _ in range(a.reps):
        t0 = time.perf_counter()
        capsflow.fmm.stokeslet(src, f, tolerance=a.tol, threads=a.threads)
        times.append(time.perf_counter() - t0)
    py_s = statistics.median(times)

    tracemalloc.start()
    capsflow.fmm.stokeslet(src, f, tolerance=a.tol, threads=a.threads)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()

    ratio = py_s / cpp_s
    print(json.dumps({"what": "python_fmm", "dist": a.dist, "n": n, "tol": a.tol, "threads": a.threads,
                      "order": cpp["order"], "reps": a.reps, "cpp_setup_s": cpp["setup_s"], "cpp_eval_s": cpp["eval_s"],
                      "cpp_s": cpp_s, "python_s": py_s, "python_all_s": times, "ratio": ratio,
                      "traced_peak_over_output": peak / (n * 3 * 8), "floor": 1.05, "pass": ratio <= 1.05}))
    return 0 if ratio <= 1.05 else 1


if __name__ == "__main__":
    sys.exit(main())
