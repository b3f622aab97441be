#!/usr/bin/env python3
"""capsflow.run of the built-in scene against `capsflow run` (floor: within 2 % of its wall time, perf/RESULTS.md §1.7).

    PYTHONPATH=BUILD/python python3 perf/python/bench_run.py --build BUILD [--reps 3] [--threads 2]

Alternates the command line and the Python call (same scene, threads and OMP_WAIT_POLICY=passive,
each into its own folder with overwrite), --reps times each, and compares the median wall times
measured around the whole call or process (set-up, steps, output, summary). Prints one JSON line.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_WAIT_POLICY", "passive")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", required=True, type=Path)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    import capsflow

    exe = a.build / "bin" / "capsflow"
    cli, py = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(a.reps):
            t0 = time.perf_counter()
            subprocess.run([str(exe), "run", "-o", f"{tmp}/cli", "--overwrite", "--threads", str(a.threads)],
                           check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            cli.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            result = capsflow.run(capsflow.Scene(), f"{tmp}/py", overwrite=True, threads=a.threads, log=False)
            py.append(time.perf_counter() - t0)
        same = json.loads(Path(f"{tmp}/cli/summary.json").read_text())["D12"] == result.summary["D12"]
    ratio = statistics.median(py) / statistics.median(cli)
    print(json.dumps({"what": "python_run", "scene": "<built-in default>", "threads": a.threads, "reps": a.reps,
                      "cli_s": cli, "python_s": py, "ratio": ratio, "same_D12": same, "floor": 1.02,
                      "pass": ratio <= 1.02}))
    return 0 if ratio <= 1.02 else 1


if __name__ == "__main__":
    sys.exit(main())
