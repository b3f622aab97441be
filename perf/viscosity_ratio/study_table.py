#!/usr/bin/env python3
# perf/RESULTS.md §2.6: tables from a study folder (capsflow study ... -o DIR): the study's own orders
# (study.csv) for D_ij, Le_i, area; the same three-level rule (p = log2(e1/e2), asymptotic when the two
# differences share a sign and p is in [0.5, 6]) applied to timeseries columns D_flow, theta, tank_treading,
# which the study does not analyse. Usage: study_table.py DIR
import csv, math, sys
d = sys.argv[1]
rows = list(csv.DictReader(open(f"{d}/study.csv")))
def fmt(x, n=6):
    return "–" if x in ("", None) else f"{float(x):.{n}g}"
print("| observable | γ̇t | L3 | L4 | L5 | p | f* | ± | \\|L5 − f*\\| | status |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---|")
for obs in ["D12", "D13", "D23", "Le1", "Le2", "Le3", "area"]:
    for r in rows:
        if r["observable"] != obs or r["time"] in ("0", "final"): continue
        t = float(r["time"])
        if obs != "D12" and abs(t - 1) > 1e-9 and abs(t - 0.4) > 1e-9: continue
        print(f"| {obs} | {t:.1f} | {fmt(r['value_L3'])} | {fmt(r['value_L4'])} | {fmt(r['value_L5'])} | {fmt(r['order'],3)} | {fmt(r['extrapolated'])} | {fmt(r['uncertainty'],2)} | {fmt(abs(float(r['error_L5'])) if r['error_L5'] else '',2)} | {r['status']} |")
series = {}
for L in (3, 4, 5):
    try:
        series[L] = {round(float(x["t"]), 6): x for x in csv.DictReader(open(f"{d}/L{L}/timeseries.csv"))}
    except FileNotFoundError:
        pass
print()
print("| observable (by hand) | γ̇t | L3 | L4 | L5 | p | f* | \\|L5 − f*\\| | status |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---|")
for obs in ["D_flow", "theta", "tank_treading"]:
    for t in (0.2, 0.4, 0.6, 0.8, 1.0):
        try:
            f = [float(series[L][t][obs]) for L in (3, 4, 5)]
        except (KeyError, ValueError):
            continue
        e1, e2 = f[1] - f[0], f[2] - f[1]
        status, p, fs, err = "non_monotone", None, None, None
        if e1 * e2 > 0:
            p = math.log2(e1 / e2)
            if 0.5 <= p <= 6:
                status = "asymptotic"
                fs = f[2] + e2 / (2 ** p - 1)
                err = abs(f[2] - fs)
            else:
                status = "non_asymptotic"
        print(f"| {obs} | {t:.1f} | {f[0]:.6g} | {f[1]:.6g} | {f[2]:.6g} | {'–' if p is None else f'{p:.2f}'} | {'–' if fs is None else f'{fs:.6g}'} | {'–' if err is None else f'{err:.2g}'} | {status} |")
