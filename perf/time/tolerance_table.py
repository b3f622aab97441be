#!/usr/bin/env python3
"""The time tolerance against the error it delivers, per paper case and mesh level.

For every case and level this runs (one simulation at a time, `--threads 1`, build/bin/capsflow):
  rkc_auto                       RKC at time.tolerance = "auto" (docs/time-integration.md §5.3)
  rock4_auto                     ROCK4 at time.tolerance = "auto" (§5.8: 2e-3 × 1280/N)
  rkc_1e-6, rkc_1e-5, rkc_5e-5   RKC at these tolerances
  heun                           Heun at its automatic step (dt_safety 0.7, the default): the cost to beat
  ref                            Heun at a quarter of the automatic step (time.dt_safety = 0.175)
  half                           Heun at half the automatic step (time.dt_safety = 0.35): checks `ref`
and compares each run's timeseries.csv with `ref` at every output time: max over outputs of
|ΔD12|, |ΔD13|, |ΔD23| and of |ΔL_i|, |ΔLe_i|; evaluations (summary.json `rhs_evaluations`, the power
iterations for ρ included) and Heun's evaluations divided by them.

Why dt_safety = 0.175 is a quarter-step reference: Heun's automatic step is dt_safety × min(calibrated
limit, 2/ρ, flow cap), recomputed before every step from the current shape (docs/time-integration.md
§5.9.2), so 0.175 = 0.7/4 takes a quarter of the automatic step at every state, not a fixed step picked
from one moment. Heun is second order: the reference's own error is about |D(half) − D(ref)|/3
(Richardson: e(h/2) − e(h/4) = (1/4 − 1/16) C h² = 3 e(h/4)), which the table reports per case.

The target (perf/RESULTS.md §2.7): at the default settings, D_ij within 1e-4 of the reference at every output time
with at least 5× fewer evaluations than `heun`. The default scheme is `auto`: ROCK4 where the analytic
spectral radius is below 800 flow rates, RKC2 above (both at time.tolerance = "auto"); to tabulate the
default, add a variant without options and name it: `--extra 'default=' --default-variant default`.
`--default-variant rkc_auto` marks RKC2's row, as binaries did where "auto" was RKC2 for every wall;
`--membrane-default-heun` marks `heun` for a membrane, for binaries where "auto" was Heun there.

Runs go to WORK/<case>_L<level>/<variant>/ and are reused when their summary.json says t_end was
reached with the same command line (WORK/.../cmd.txt); delete a folder to redo it.
Writes OUT.jsonl (one line per run) and OUT.md (the table).

Usage:
  perf/time/tolerance_table.py --levels 3 [--cases fig4,builtin,...] [--work build/tolerance_runs]
                               [--out perf/time/tolerance_L3] [--variants rkc_1e-6,heun,ref,...]
                               [--extra NAME='--set k=v ...'] [--dry-run] [--no-run]
  --extra: leading NAME=VALUE words set the environment of that run, EXE=path runs another binary
  (perf/time/tolerance_L3_norms.* came from an experimental binary: docs/time-integration.md §5.6).
  The reference must be run by the same --exe, since a run is reused only if its command matches.
"""
import argparse
import csv
import json
import math
import os
import shlex
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# name -> (scene file relative to the repo or None for the built-in scene, extra options, description)
CASES = {
    "table1_gsmb3": ("scenes/paper_table1_nh_gsmb_alpha3.toml", [], "Table 1, GSMB NH α = 3 %"),
    "table1_gsmb10": ("scenes/paper_table1_nh_gsmb_alpha10.toml", [], "Table 1, GSMB NH α = 10 %"),
    "table1_membrane": ("scenes/paper_table1_nh_membrane.toml", [], "Table 1, NH membrane"),
    "fig4": ("scenes/paper_fig4_gh_alpha3.toml", [], "Fig. 4, GSMB GH α = 3 %"),
    "builtin": (None, [], "built-in scene (scenes/quick.toml)"),
    # The a/b = 4 spheroid of TimeSchemes.RkcIsStableOnTheAspectFourSpheroid: the built-in scene, aspect 4.
    "ab4": (None, ["--set", "mesh.aspect=4"], "built-in scene at a/b = 4"),
    # The large-deformation membrane benchmark (scenes/sphere_nh_shear_ca06.toml), to γ̇t = 8: Ca_s = 0.6, a soft membrane.
    "nh_ca06": ("scenes/sphere_nh_shear_ca06.toml", [], "NH membrane sphere, Ca_s = 0.6 (large deformation)"),
    # λ ≠ 1 (the double layer's second-kind solve), run to γ̇t = 5 rather than to their steady state
    "lambda02": ("scenes/sphere_shear_lambda02.toml", ["--set", "time.stop_at_steady=false"], "NH sphere in shear, λ = 0.2"),
    "lambda5": ("scenes/sphere_shear_lambda5.toml", ["--set", "time.stop_at_steady=false"], "NH sphere in shear, λ = 5"),
}
# Cases' own t_end (scenes/quick.toml: 2; the large-deformation benchmark: 8); the paper scenes end at 5.
CASE_T_END = {"builtin": 2.0, "ab4": 2.0, "nh_ca06": 8.0}
T_END_DEFAULT = 5.0

VARIANTS = {
    "rkc_auto": ["--set", "time.scheme=rkc"],
    "rock4_auto": ["--set", "time.scheme=rock4"],  # ROCK4 at its own "auto" tolerance (§5.8)
    "rkc_1e-6": ["--set", "time.scheme=rkc", "--set", "time.tolerance=1e-6"],
    "rkc_1e-5": ["--set", "time.scheme=rkc", "--set", "time.tolerance=1e-5"],
    "rkc_5e-5": ["--set", "time.scheme=rkc", "--set", "time.tolerance=5e-5"],
    "heun": ["--set", "time.scheme=heun"],
    "ref": ["--set", "time.scheme=heun", "--set", "time.dt_safety=0.175"],
    "half": ["--set", "time.scheme=heun", "--set", "time.dt_safety=0.35"],
}
ORDER = ["heun", "ref", "half", "rkc_auto", "rock4_auto", "rkc_1e-6", "rkc_1e-5", "rkc_5e-5"]
D_COLS = ["D12", "D13", "D23"]
L_COLS = ["L1", "L2", "L3", "Le1", "Le2", "Le3"]
ITEM_ERROR = 1e-4
ITEM_GAIN = 5.0
MEMBRANE_DEFAULT_HEUN = False  # --membrane-default-heun
DEFAULT_VARIANT = "rkc_auto"  # --default-variant: the row that the binary's defaults run


def run_one(exe, case, level, variant, opts, work, dry):
    scene, case_opts, _ = CASES[case]
    t_end = CASE_T_END.get(case, T_END_DEFAULT)
    folder = os.path.join(work, f"{case}_L{level}", variant)
    # Leading NAME=VALUE words of a variant set the environment (EXE=path: another binary).
    env, opts = dict(os.environ), list(opts)
    prefix = []
    while opts and "=" in opts[0] and opts[0].split("=", 1)[0].isupper():
        k, v = opts.pop(0).split("=", 1)
        prefix.append(f"{k}={v}")
        if k == "EXE":
            exe = v
        else:
            env[k] = v
    cmd = [exe, "run"] + ([os.path.join(ROOT, scene)] if scene else []) + case_opts
    cmd += ["--set", f"mesh.level={level}", "--set", f"time.t_end={t_end:g}"] + opts
    cmd += ["--threads", "1", "-o", folder, "--overwrite"]
    line = " ".join([p for p in prefix if not p.startswith("EXE=")] + [shlex.quote(c) for c in cmd])
    summary = os.path.join(folder, "summary.json")
    cmd_file = folder + ".cmd"
    if os.path.exists(summary) and os.path.exists(cmd_file) and open(cmd_file).read().strip() == line:
        s = json.load(open(summary))
        if s.get("stop_reason") == "t_end":
            return folder, line, "reused"
    if dry:
        print("would run:", line)
        return folder, line, "dry"
    os.makedirs(os.path.dirname(folder), exist_ok=True)
    print(f"[{time.strftime('%H:%M:%S')}] {case} L{level} {variant}: {line}", flush=True)
    with open(folder + ".log", "w") as log:
        rc = subprocess.call(cmd, stdout=log, stderr=subprocess.STDOUT, env=env)
    with open(cmd_file, "w") as f:
        f.write(line + "\n")
    print(f"[{time.strftime('%H:%M:%S')}]   exit {rc}", flush=True)
    return folder, line, f"exit {rc}"


def read_series(folder):
    rows = {}
    with open(os.path.join(folder, "timeseries.csv")) as f:
        for r in csv.DictReader(f):
            rows[round(float(r["t"]), 9)] = r
    return rows


def compare(run, ref):
    """max over common output times of |Δ| for D_ij and L_i/Le_i; the times compared."""
    common = sorted(set(run) & set(ref))
    worst_d, worst_d_at, worst_l = 0.0, None, 0.0
    for t in common:
        for c in D_COLS:
            d = abs(float(run[t][c]) - float(ref[t][c]))
            if d > worst_d:
                worst_d, worst_d_at = d, (c, t)
        for c in L_COLS:
            worst_l = max(worst_l, abs(float(run[t][c]) - float(ref[t][c])))
    return worst_d, worst_d_at, worst_l, len(common)


def fold_indicators(s):
    h = s.get("health", {})
    return {
        "facet_angle_max": h.get("facet_angle_max"),
        "grid_oscillation_max": h.get("grid_oscillation_max"),
        "grid_oscillation_threshold": h.get("grid_oscillation_threshold"),
        "min_facet_angle": h.get("min_facet_angle"),
        "warnings": [w.get("condition", str(w)) + (f" (γ̇t = {w['t']:.2f})" if "t" in w else "")
                     if isinstance(w, dict) else str(w) for w in h.get("warnings", [])],
    }


def first_fold_time(folder, s):
    """First output time where the grid-scale indicator exceeds its threshold (the health monitor's rule)."""
    thr = s.get("health", {}).get("grid_oscillation_threshold")
    if thr is None:
        return None
    for t, r in sorted(read_series(folder).items()):
        try:
            if float(r["grid_oscillation"]) > thr:
                return t
        except (KeyError, ValueError):
            pass
    return None


def fmt(x, spec=".2g"):
    return "–" if x is None else format(x, spec)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--exe", default=os.path.join(ROOT, "build", "bin", "capsflow"))
    ap.add_argument("--levels", default="3")
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--variants", default=",".join(ORDER))
    ap.add_argument("--extra", action="append", default=[],
                    help="NAME='options': one more variant, e.g. rkc_x='--set time.scheme=rkc --set time.tolerance=2e-6'")
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "tolerance_runs"))
    ap.add_argument("--out", default=None, help="prefix of OUT.jsonl and OUT.md (default perf/time/tolerance_L<levels>)")
    ap.add_argument("--dry-run", action="store_true")
    ap.add_argument("--no-run", action="store_true", help="only tabulate the runs that exist")
    ap.add_argument("--default-variant", default="rkc_auto",
                    help="the variant that runs the binary's default scheme and tolerance (rkc_auto, rock4_auto)")
    ap.add_argument("--membrane-default-heun", action="store_true",
                    help="mark Heun as a membrane's default (binaries where \"auto\" was Heun for a membrane)")
    a = ap.parse_args()
    global MEMBRANE_DEFAULT_HEUN, DEFAULT_VARIANT
    MEMBRANE_DEFAULT_HEUN = a.membrane_default_heun
    DEFAULT_VARIANT = a.default_variant

    variants = dict(VARIANTS)
    order = [v for v in a.variants.split(",") if v]
    for e in a.extra:
        name, opts = e.split("=", 1)
        variants[name] = shlex.split(opts)
        order.append(name)
    for need in ("ref",):
        if need not in order:
            order.insert(0, need)
    levels = [int(x) for x in a.levels.split(",")]
    cases = [c for c in a.cases.split(",") if c]
    out = a.out or os.path.join(ROOT, "perf", "time", "tolerance_L" + "_".join(map(str, levels)))

    records = []
    for level in levels:
        for case in cases:
            runs = {}
            for v in order:
                folder, line, how = (None, None, None)
                if a.no_run:
                    folder = os.path.join(a.work, f"{case}_L{level}", v)
                    cf = folder + ".cmd"
                    line = open(cf).read().strip() if os.path.exists(cf) else None
                    how = "existing"
                else:
                    folder, line, how = run_one(a.exe, case, level, v, variants[v], a.work, a.dry_run)
                sp = os.path.join(folder, "summary.json")
                if os.path.exists(sp):
                    runs[v] = (folder, line, json.load(open(sp)))
            if a.dry_run or "ref" not in runs:
                continue
            ref_series = read_series(runs["ref"][0])
            heun_evals = runs["heun"][2].get("rhs_evaluations") if "heun" in runs else None
            for v in order:
                if v not in runs:
                    continue
                folder, line, s = runs[v]
                wd, wd_at, wl, n = compare(read_series(folder), ref_series)
                ev = s.get("rhs_evaluations")
                rec = {
                    "case": case, "level": level, "elements": s.get("elements"), "variant": v,
                    "scheme": s.get("scheme"), "tolerance": s.get("scene", {}).get("time", {}).get("tolerance"),
                    "auto_tolerance": s.get("time_tolerance"),
                    "dt_safety": s.get("scene", {}).get("time", {}).get("dt_safety"),
                    "t_end": s.get("t"), "stop_reason": s.get("stop_reason"),
                    "rhs_evaluations": ev, "steps": s.get("steps"), "rejected_steps": s.get("rejected_steps"),
                    "spectral_radius_evaluations": s.get("spectral_radius_evaluations"),
                    "heun_evaluations": heun_evals,
                    "fewer_than_heun": (heun_evals / ev) if (heun_evals and ev) else None,
                    "max_dD": wd, "max_dD_at": wd_at, "max_dL_Le": wl, "outputs_compared": n,
                    "outputs_in_ref": len(ref_series),
                    "volume_drift": s.get("volume_drift"),
                    "fold": fold_indicators(s), "first_fold_t": first_fold_time(folder, s),
                    "git": s.get("git"), "command": (line or "").replace(ROOT + "/", ""),
                }
                records.append(rec)

    if a.dry_run:
        return
    os.makedirs(os.path.dirname(out), exist_ok=True)
    with open(out + ".jsonl", "w") as f:
        for r in records:
            f.write(json.dumps(r, ensure_ascii=False) + "\n")
    with open(out + ".md", "w") as f:
        f.write(compact_table(records) + "\n" + table(records))
    sys.stdout.write(compact_table(records) + "\n" + table(records))


def table(records):
    lines = ["| case | elements | run | evaluations | × fewer than Heun | max \\|ΔD_ij\\| (where) | "
             "max \\|ΔL_i, ΔLe_i\\| | outputs | item |",
             "|---|---:|---|---:|---:|---:|---:|---:|---|"]
    by_case = {}
    for r in records:
        by_case.setdefault((r["case"], r["level"]), []).append(r)
    for (case, level), rs in by_case.items():
        half = next((r for r in rs if r["variant"] == "half"), None)
        heun = next((r for r in rs if r["variant"] == "heun"), None)
        membrane = heun is not None and CASES[case][0] is not None and "membrane" in CASES[case][0]
        default = "heun" if membrane and MEMBRANE_DEFAULT_HEUN else DEFAULT_VARIANT
        for r in rs:
            if r["variant"] == "ref":
                continue
            where = f"{r['max_dD_at'][0]} at {r['max_dD_at'][1]:g}" if r["max_dD_at"] else ""
            name = r["variant"] + (" (default)" if r["variant"] == default else "")
            if r["variant"] == "half":
                name += f"; ref's own error ≈ {r['max_dD'] / 3:.1g}"
            verdict = ""
            if r["variant"] not in ("half",):
                ok_e = r["max_dD"] <= ITEM_ERROR and r["outputs_compared"] == r["outputs_in_ref"]
                ok_g = (r["fewer_than_heun"] or 0) >= ITEM_GAIN
                verdict = ("error ok" if ok_e else "ERROR > 1e-4") + (", ≥ 5×" if ok_g else ", < 5×")
            f = r["fold"]
            lines.append(
                f"| {CASES[case][2]} | {r['elements']} | {name} | {r['rhs_evaluations']} | "
                f"{fmt(r['fewer_than_heun'], '.1f')} | {fmt(r['max_dD'])} ({where}) | {fmt(r['max_dL_Le'])} | "
                f"{r['outputs_compared']}/{r['outputs_in_ref']} | {verdict} |")
        ref = next((r for r in rs if r["variant"] == "ref"), None)
        if ref:
            f = ref["fold"]
            lines.append(
                f"| | | fold indicators (reference run): facet angle max {fmt(f['facet_angle_max'], '.0f')}°, "
                f"grid-scale max {fmt(f['grid_oscillation_max'], '.3f')} (threshold {fmt(f['grid_oscillation_threshold'], '.3f')}, "
                f"first above at γ̇t = {fmt(ref['first_fold_t'], 'g')}), warnings {', '.join(map(str, f['warnings'])) or 'none'} | | | | | | |")
    return "\n".join(lines) + "\n"


def compact_table(records):
    """One row per case: each RKC variant as 'evaluations (× fewer than Heun), max |ΔD_ij|'."""
    by_case, variants = {}, []
    for r in records:
        by_case.setdefault((r["case"], r["level"]), {})[r["variant"]] = r
        if r["variant"] not in ("ref", "half", "heun") and r["variant"] not in variants:
            variants.append(r["variant"])
    head = "| case | elements, to γ̇t | Heun automatic: evaluations, max \\|ΔD_ij\\| | reference's own error | " + \
        " | ".join(f"{v}: evaluations (×), max \\|ΔD_ij\\|" for v in variants) + " | folds (reference run) |"
    lines = [head, "|---|---|---|---|" + "---|" * len(variants) + "---|"]
    for (case, level), rs in by_case.items():
        heun, half, ref = rs.get("heun"), rs.get("half"), rs.get("ref")
        cells = [CASES[case][2], f"{ref['elements']}, {ref['t_end']:g}" if ref else "",
                 f"{heun['rhs_evaluations']}, {heun['max_dD']:.1e}" if heun else "–",
                 f"{half['max_dD'] / 3:.0e}" if half else "not run"]
        for v in variants:
            r = rs.get(v)
            if not r:
                cells.append("–")
                continue
            bad = r["max_dD"] > ITEM_ERROR or r["outputs_compared"] != r["outputs_in_ref"]
            x = f"{r['fewer_than_heun']:.1f}×" if r["fewer_than_heun"] else "–"
            cells.append(f"{r['rhs_evaluations']} ({x}), {'**' if bad else ''}{r['max_dD']:.1e}{'**' if bad else ''}")
        f = ref["fold"] if ref else None
        cells.append("–" if not f else
                     f"facet ≤ {f['facet_angle_max']:.0f}°, grid-scale ≤ {f['grid_oscillation_max']:.2f} " +
                     (f"(> {f['grid_oscillation_threshold']:.3f} from γ̇t = {ref['first_fold_t']:g})" if ref["first_fold_t"] is not None
                      else f"(never > {f['grid_oscillation_threshold']:.3f})"))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
