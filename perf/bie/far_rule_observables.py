#!/usr/bin/env python3
"""far_rule_observables.py — does the edge-midpoint far field move the observables? (perf/RESULTS.md §2.2)

For each mesh level, two runs of the same scene that differ only in `fluid.far_rule` ("auto": one
source per edge midpoint on flat facets; "gauss_points": three Gauss points per element, the far
field before the edge-midpoint rule). Every D_ij, L_i, Le_i at the given times is compared, and the difference
is judged against max(1e-5, a tenth of the discretisation error that `capsflow study` measured at
that level (its study.csv: error_L<level> = value − extrapolated limit, per observable and time;
where the study found no limit, the change to the next level, marked Δ).

    capsflow run scenes/paper_fig4_gh_alpha3.toml -o DIR/L4_auto --threads 2 --set mesh.level=4 --set fluid.far_rule=\\"auto\\"
    capsflow run scenes/paper_fig4_gh_alpha3.toml -o DIR/L4_gauss_points --threads 2 --set mesh.level=4 --set fluid.far_rule=\\"gauss_points\\"
    perf/bie/far_rule_observables.py DIR --levels 3,4,5 --study perf/solver/study_fig4/study.csv --family geometry=flat

Standard library only; prints a markdown table and exits 1 if a difference exceeds its bound.
"""
import argparse
import csv
import math
import pathlib
import sys

OBSERVABLES = ["D12", "D13", "D23", "L1", "L2", "L3", "Le1", "Le2", "Le3"]


def row_at(path, t):
    """The timeseries row whose time is nearest to t (outputs land on their times)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    best = min(rows, key=lambda r: abs(float(r["t"]) - t))
    if abs(float(best["t"]) - t) > 1e-6:
        sys.exit(f"{path}: no output at t = {t} (nearest {best['t']})")
    return best


def study_errors(path, family):
    """(observable, time) -> {level: |error|} from a capsflow study.csv."""
    out = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            if r["family"] != family or r["time"] in ("final", ""):
                continue
            errs, values = {}, {}
            for k, v in r.items():
                if k.startswith("error_L") and v not in ("", None):
                    errs[int(k[len("error_L"):])] = (abs(float(v)), "")
                if k.startswith("value_L") and v not in ("", None):
                    values[int(k[len("value_L"):])] = float(v)
            # Without an extrapolated limit (non-monotone or non-asymptotic), the change to the
            # next finer level stands in for the error at this one (marked "Δ").
            for level, v in values.items():
                if level not in errs and level + 1 in values:
                    errs[level] = (abs(values[level + 1] - v), "Δ")
            out[(r["observable"], round(float(r["time"]), 6))] = errs
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", type=pathlib.Path, help="folder holding L<level>_auto and L<level>_gauss_points")
    ap.add_argument("--levels", default="3,4,5")
    ap.add_argument("--times", default="1,5")
    ap.add_argument("--study", type=pathlib.Path, required=True, help="study.csv of `capsflow study`")
    ap.add_argument("--family", default="geometry=flat")
    a = ap.parse_args()
    errs = study_errors(a.study, a.family)
    worst_ratio, failed = 0.0, False
    print("| level | γ̇t | observable | edge midpoints | Gauss points (6N) | difference | study's error at the level | bound | ok |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---|")
    for level in [int(x) for x in a.levels.split(",")]:
        for t in [float(x) for x in a.times.split(",")]:
            ra = row_at(a.runs / f"L{level}_auto" / "timeseries.csv", t)
            rg = row_at(a.runs / f"L{level}_gauss_points" / "timeseries.csv", t)
            for o in OBSERVABLES:
                va, vg = float(ra[o]), float(rg[o])
                d = abs(va - vg)
                e, mark = errs.get((o, round(t, 6)), {}).get(level, (None, ""))
                bound = max(1e-5, 0.1 * e) if e is not None and math.isfinite(e) else 1e-5
                ok = d <= bound
                failed |= not ok
                worst_ratio = max(worst_ratio, d / bound)
                es = f"{e:.1e}{' ' + mark if mark else ''}" if e is not None else "—"
                print(f"| {level} | {t:g} | {o} | {va:.8f} | {vg:.8f} | {d:.1e} | {es} | {bound:.1e} | {'yes' if ok else '**no**'} |")
    print(f"\nlargest difference / bound: {worst_ratio:.2f}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
