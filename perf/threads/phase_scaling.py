#!/usr/bin/env python3
"""Thread scaling by phase: the same short run on 1 and on 2 threads, several times each, and per
phase of an evaluation (summary.json timing.phases and cpu_seconds) the median wall seconds, the
speed-up, cpu/wall on 2 threads and the parallel fraction p that Amdahl's law gives from the
speed-up S on 2 threads (S = 1 / ((1 − p) + p/2), p = 2 (1 − 1/S)), with the speed-up that p
predicts on 4, 8 and 16 threads. Run alone on the machine.

  perf/threads/phase_scaling.py [--exe build/bin/capsflow] [--repeats 3] [--out DIR] -- [capsflow run options]

Default run: the paper's Fig. 4 case at 81 920 elements to γ̇t = 0.05 (about 40 evaluations,
the set-up included in "other").
"""
import argparse
import json
import os
import statistics
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_RUN = [os.path.join(ROOT, "scenes", "paper_fig4_gh_alpha3.toml"), "--set", "mesh.level=6", "--set", "time.t_end=0.05"]


def run(exe, args, threads, folder):
    subprocess.run([exe, "run", *args, "--threads", str(threads), "-o", folder, "--overwrite"], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return json.load(open(os.path.join(folder, "summary.json")))["timing"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--exe", default=os.path.join(ROOT, "build", "bin", "capsflow"))
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default="/tmp/capsflow-phase-scaling")
    ap.add_argument("run", nargs="*")
    a = ap.parse_args()
    args = a.run or DEFAULT_RUN
    timings = {1: [], 2: []}
    for r in range(a.repeats):
        for threads in (1, 2):  # alternated, so that a drift of the machine touches both alike
            timings[threads].append(run(a.exe, args, threads, os.path.join(a.out, f"t{threads}_r{r}")))
    phases = sorted(timings[1][0]["phases"])
    print(f"evaluations per run: {timings[2][0]['rhs_evaluations']}; medians of {a.repeats} runs")
    print("| phase | 1 thread (s) | 2 threads (s) | speed-up | cpu/wall on 2 | parallel fraction p | S(4) | S(8) | S(16) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    rows = phases + ["total"]
    for ph in rows:
        def wall(t):
            return t["total_seconds"] if ph == "total" else t["phases"][ph]

        def cpu(t):
            return t["total_cpu_seconds"] if ph == "total" else t["cpu_seconds"][ph]

        w1 = statistics.median(wall(t) for t in timings[1])
        w2 = statistics.median(wall(t) for t in timings[2])
        c2 = statistics.median(cpu(t) / wall(t) if wall(t) > 0 else 0 for t in timings[2])
        if w1 < 1e-3 or w2 < 1e-3:
            continue
        s = w1 / w2
        p = 2 * (1 - 1 / s)
        pred = [1 / ((1 - p) + p / n) if p < 1 else float(n) for n in (4, 8, 16)]
        print(f"| {ph} | {w1:.2f} | {w2:.2f} | {s:.2f} | {c2:.2f} | {p:.3f} | " + " | ".join(f"{x:.1f}" for x in pred) + " |")


if __name__ == "__main__":
    main()
