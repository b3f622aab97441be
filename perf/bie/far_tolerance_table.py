#!/usr/bin/env python3
"""The far-field tolerance against the error it leaves in the observables, per paper case and mesh.

For every case, level and back end this runs the case at its default settings (scheme and time
tolerance "auto") with fluid.tolerance = 1e-8 (the reference) and at each tolerance asked for, one
run at a time on --threads 2, and compares each run's timeseries.csv with the reference's at every
output time: max over outputs of |ΔD12|, |ΔD13|, |ΔD23|; and the evaluations and wall time
(summary.json). The observables' budget is the time tolerance's (D_ij within 1e-4 of a converged
reference, docs/time-integration.md §5.2): a far-field tolerance is good for a case when it adds
a small part of that.

Runs go to WORK/<case>_L<level>_<backend>/tol_<tolerance>/ and are reused when their summary.json says
t_end was reached with the same command line. Writes OUT.jsonl (one line per run) and OUT.md; with
--append the rows join those already in OUT.jsonl (a row of the same case, level, back end and
tolerance is replaced), and OUT.md shows them all.

Usage:
  perf/bie/far_tolerance_table.py [--levels 3,4] [--cases fig4,table1_gsmb3,...] [--backends direct,fmm]
                                  [--tolerances 1e-6,1e-5,1e-4,1e-3] [--work build/far_tolerance_runs]
                                  [--out perf/bie/far_tolerance] [--append]
"""
import argparse
import csv
import json
import os
import shlex
import subprocess
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CASES = {
    "table1_gsmb3": ("scenes/paper_table1_nh_gsmb_alpha3.toml", "Table 1, GSMB NH α = 3 %"),
    "table1_gsmb10": ("scenes/paper_table1_nh_gsmb_alpha10.toml", "Table 1, GSMB NH α = 10 %"),
    "table1_membrane": ("scenes/paper_table1_nh_membrane.toml", "Table 1, NH membrane"),
    "fig4": ("scenes/paper_fig4_gh_alpha3.toml", "Fig. 4, GSMB GH α = 3 %"),
}
T_END = 5.0
REFERENCE = "1e-8"
D_COLS = ["D12", "D13", "D23"]


def run_one(exe, case, level, backend, tol, work):
    folder = os.path.join(work, f"{case}_L{level}_{backend}", f"tol_{tol}")
    cmd = [exe, "run", os.path.join(ROOT, CASES[case][0]), "--set", f"mesh.level={level}", "--set", f"time.t_end={T_END:g}",
           "--set", f"fluid.backend={backend}", "--set", f"fluid.tolerance={tol}", "--threads", "2", "-o", folder, "--overwrite"]
    line = " ".join(shlex.quote(c) for c in cmd)
    summary = os.path.join(folder, "summary.json")
    if os.path.exists(summary) and os.path.exists(folder + ".cmd") and open(folder + ".cmd").read().strip() == line:
        if json.load(open(summary)).get("stop_reason") == "t_end":
            return folder
    os.makedirs(os.path.dirname(folder), exist_ok=True)
    print(f"[{time.strftime('%H:%M:%S')}] {case} L{level} {backend} {tol}", flush=True)
    with open(folder + ".log", "w") as log:
        rc = subprocess.call(cmd, stdout=log, stderr=subprocess.STDOUT)
    with open(folder + ".cmd", "w") as f:
        f.write(line + "\n")
    if rc != 0:
        print(f"    exit {rc}: {folder}.log", flush=True)
    return folder


def series(folder):
    with open(os.path.join(folder, "timeseries.csv")) as f:
        return {round(float(r["t"]), 9): r for r in csv.DictReader(f)}


def worst_difference(run, ref):
    common = sorted(set(run) & set(ref))
    return max((abs(float(run[t][c]) - float(ref[t][c])) for t in common for c in D_COLS), default=float("nan")), len(common)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--exe", default=os.path.join(ROOT, "build", "bin", "capsflow"))
    ap.add_argument("--levels", default="3,4")
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--backends", default="direct,fmm")
    ap.add_argument("--tolerances", default="1e-6,1e-5,1e-4,1e-3")
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "far_tolerance_runs"))
    ap.add_argument("--out", default=os.path.join(ROOT, "perf", "bie", "far_tolerance"))
    ap.add_argument("--append", action="store_true", help="keep the rows already in OUT.jsonl")
    a = ap.parse_args()
    rows = []
    for case in filter(None, a.cases.split(",")):  # --cases "" --append: render OUT.md only
        for level in [int(x) for x in a.levels.split(",")]:
            for backend in a.backends.split(","):
                ref = run_one(a.exe, case, level, backend, REFERENCE, a.work)
                ref_series = series(ref)
                for tol in a.tolerances.split(","):
                    folder = run_one(a.exe, case, level, backend, tol, a.work)
                    s = json.load(open(os.path.join(folder, "summary.json")))
                    d, n = worst_difference(series(folder), ref_series)
                    rows.append({"case": case, "level": level, "elements": s.get("elements"), "backend": backend,
                                 "tolerance": float(tol), "max_dD": d, "outputs": n, "stop_reason": s.get("stop_reason"),
                                 "evaluations": s.get("rhs_evaluations"), "wall_seconds": s.get("wall_seconds"),
                                 "fmm_order": s.get("fmm_order")})
                    print(f"    {case} L{level} {backend} {tol}: max |ΔD_ij| {d:.2e} over {n} outputs", flush=True)
    if a.append and os.path.exists(a.out + ".jsonl"):
        key = lambda r: (r["case"], r["level"], r["backend"], r["tolerance"])
        new_keys = {key(r) for r in rows}
        rows = [r for r in map(json.loads, open(a.out + ".jsonl")) if key(r) not in new_keys] + rows
    with open(a.out + ".jsonl", "w") as f:
        for r in rows:
            f.write(json.dumps(r) + "\n")
    tols = sorted({f"{r['tolerance']:g}" for r in rows}, key=float)
    with open(a.out + ".md", "w") as f:
        f.write("max |ΔD_ij| over the outputs to γ̇t = 5 against fluid.tolerance = 1e-8 (evaluations)\n\n")
        f.write("| case | elements | back end | " + " | ".join(tols) + " |\n|---|---:|---|" + "---:|" * len(tols) + "\n")
        keys = sorted({(r["case"], r["level"], r["backend"]) for r in rows})
        for case, level, backend in keys:
            cells = []
            for tol in tols:
                r = next((r for r in rows if (r["case"], r["level"], r["backend"]) == (case, level, backend)
                          and r["tolerance"] == float(tol)), None)
                cells.append("–" if r is None else f"{r['max_dD']:.1e} ({r['evaluations']})")
            elements = next(r["elements"] for r in rows if (r["case"], r["level"]) == (case, level))
            f.write(f"| {CASES[case][1]} | {elements} | {backend} | " + " | ".join(cells) + " |\n")
    print("wrote", a.out + ".jsonl", a.out + ".md")


if __name__ == "__main__":
    main()
