#!/usr/bin/python3
"""Stress campaign: run capsflow over a matrix of capillary numbers, laws, walls, shapes
and flows, and record how each run ends, what the health monitors saw and what it cost.

    perf/stress/campaign.py --matrix small -o stress-out        # the small matrix of perf/RESULTS.md §3.2
    perf/stress/campaign.py --matrix full  -o stress-out        # the full sweep (hours)

Every run is an ordinary `capsflow run` in OUT/<name>/ with `time.stop_on` set to every health
condition, so a run ends at the first sign of trouble with a named stop_reason. Finished runs are
skipped when the campaign is started again. Writes OUT/results.csv, OUT/results.md and
OUT/stability_map.png (outcome against Ca_s, one row per configuration).
"""
import argparse
import csv
import io
import itertools
import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
EXE = os.path.join(HERE, "..", "..", "build", "bin", "capsflow")
CONDITIONS = ["mesh_scale_buckling", "unresolved_folds", "element_quality", "no_equilibrium"]

NH, GH, MR = ("nh", {}), ("gh", {}), ("mr", {"wall.mooney_rivlin_psi": 0.1})
SK1, SK10 = ("skalak", {"wall.skalak_c": 1}), ("skalak", {"wall.skalak_c": 10})
MEMBRANE, GSMB3 = ("membrane", None), ("gsmb", 0.03)
SPHERE, BOTH_FLOWS = [("sphere", 1.0)], ["simple_shear", "planar_hyperbolic"]
PARAMETER_LABEL = {"wall.skalak_c": "C", "wall.mooney_rivlin_psi": "Ψ"}
CA_ALL = [1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3, 1.0, 3.0, 10.0]
CA_DECADES = [1e-3, 1e-2, 0.1, 1.0, 10.0]

# A matrix is a list of blocks; each block is a full product of its lists. Runs named twice run once.
MATRICES = {
    # 1280 elements, to γ̇t = 3: a strain-softening and a strain-hardening law, both wall families,
    # both flows, two shapes, Ca_s over four decades (48 runs, ≈ 15 min on 2 cores).
    "small": [dict(ca=[1e-3, 0.1, 10.0], level=[3], t_end=3.0, steady=False, walls=[MEMBRANE, GSMB3], laws=[NH, SK10],
                   shapes=[("sphere", 1.0), ("spheroid", 2.0)], flows=BOTH_FLOWS)],
    # The full sweep as blocks that vary one factor at a time around the NH sphere (the full product
    # of every factor, 9 × 5 × 5 × 4 × 2 × 2 = 3600 runs per level, would take days on 2 cores).
    # To γ̇t = 5, stopping at a steady state; the cheap and the telling runs first (1280 elements, the
    # shells past their folds, 5120 elements at Ca_s ≥ 0.1, a few at 20 480), the stiff ones last, so a
    # campaign cut short still has complete blocks.
    "full": [
        # Ca_s in half-decade steps for the membrane and every GSMB thickness.
        dict(ca=CA_ALL, level=[3], walls=[MEMBRANE, ("gsmb", 0.01), GSMB3, ("gsmb", 0.1), ("gsmb", 0.2)], laws=[NH],
             shapes=SPHERE, flows=BOTH_FLOWS),
        # Every law, both wall families.
        dict(ca=CA_DECADES, level=[3], walls=[MEMBRANE, GSMB3], laws=[GH, SK1, SK10, MR], shapes=SPHERE, flows=BOTH_FLOWS),
        # Every spheroid, a softening and a hardening law (a/b = 4 at the two smallest Ca_s last: it
        # tumbles, never steadies and costs ~10 min per run).
        dict(ca=CA_DECADES, level=[3], walls=[MEMBRANE, GSMB3], laws=[NH, SK10],
             shapes=[("spheroid", 1.4), ("spheroid", 2.0)], flows=BOTH_FLOWS),
        dict(ca=[0.1, 1.0, 10.0], level=[3], walls=[MEMBRANE, GSMB3], laws=[NH, SK10], shapes=[("spheroid", 4.0)],
             flows=BOTH_FLOWS),
        # Past the folds: a shell stopping only on no_equilibrium and element_quality (the fold flags are
        # still recorded as warnings), to γ̇t = 10 — where does a strain-softening law lose its equilibrium?
        dict(ca=[0.3, 1.0, 3.0, 10.0], level=[3], walls=[GSMB3], laws=[NH, SK10, MR], shapes=SPHERE, flows=BOTH_FLOWS,
             t_end=10.0, stop_on=["no_equilibrium", "element_quality"], tag="past_folds"),
        # The paper's resolution, the moderate and large Ca_s first.
        dict(ca=[0.1, 1.0, 10.0], level=[4], walls=[MEMBRANE, GSMB3], laws=[NH], shapes=[("sphere", 1.0), ("spheroid", 2.0)],
             flows=BOTH_FLOWS),
        dict(ca=[0.1, 1.0, 10.0], level=[4], walls=[MEMBRANE, GSMB3], laws=[SK10], shapes=SPHERE, flows=BOTH_FLOWS),
        # 20 480 elements: does the verdict at the two ends of the Ca_s range hold one level up?
        dict(ca=[0.1, 10.0], level=[5], walls=[MEMBRANE, GSMB3], laws=[NH], shapes=SPHERE, flows=["simple_shear"]),
        # The thinnest shell folds at Ca_s = 0.01–0.03 at 1280 elements where α ≥ 3 % does not: one level up.
        dict(ca=[0.01, 0.03], level=[4], walls=[("gsmb", 0.01)], laws=[NH], shapes=SPHERE, flows=["planar_hyperbolic"]),
        dict(ca=[1e-3, 1e-2], level=[4], walls=[MEMBRANE, GSMB3], laws=[NH], shapes=[("sphere", 1.0), ("spheroid", 2.0)],
             flows=BOTH_FLOWS),
        dict(ca=[1e-3, 1e-2], level=[4], walls=[MEMBRANE, GSMB3], laws=[SK10], shapes=SPHERE, flows=BOTH_FLOWS),
        dict(ca=[1e-3, 1e-2], level=[3], walls=[MEMBRANE, GSMB3], laws=[NH, SK10], shapes=[("spheroid", 4.0)],
             flows=BOTH_FLOWS),
    ],
}


def runs(matrix, scheme="auto"):
    seen = set()
    for m in matrix:
        t_end, steady, stop_on = m.get("t_end", 5.0), m.get("steady", True), m.get("stop_on", CONDITIONS)
        for level, ca, (wall, alpha), (law, extra), (shape, aspect), flow in itertools.product(
                m["level"], m["ca"], m["walls"], m["laws"], m["shapes"], m["flows"]):
            name = f"L{level}_{wall}{'' if alpha is None else f'{alpha:g}'}_{law}{''.join(f'{v:g}' for v in extra.values())}" \
                   f"_{shape}{aspect:g}_{flow}_ca{ca:g}" + (f"_{m['tag']}" if "tag" in m else "")
            if name in seen:
                continue
            seen.add(name)
            sets = {"mesh.level": level, "mesh.shape": shape, "wall.model": wall, "wall.law": law, "flow.type": flow,
                    "flow.ca_s": ca, "time.t_end": t_end, "output.every": 0.1, "output.checkpoint_every": 1.0,
                    "time.stop_on": "[" + ",".join(f'"{c}"' for c in stop_on) + "]",
                    # The default, "auto" (ROCK4 or RKC2 by the wall's stiffness on its mesh), unless
                    # --scheme names one (the older tables in perf/stress/results.md and full/ ran rkc).
                    "time.scheme": scheme}
            if steady:
                sets["time.stop_at_steady"] = "true"
            if shape == "spheroid":
                sets["mesh.aspect"] = aspect
            if alpha is not None:
                sets["wall.thickness"] = alpha
            sets.update(extra)
            law_label = law + "".join(f" {PARAMETER_LABEL[k]}={v:g}" for k, v in extra.items())
            yield name, dict(ca=ca, level=level, wall=wall if alpha is None else f"gsmb {alpha:g}", law=law_label,
                             shape=f"{shape} {aspect:g}", flow=flow, stops_on="all" if "tag" not in m else m["tag"]), sets


def picked_scheme(exe, sets):
    """The scheme `capsflow info` says the run would take (time.scheme = "auto" picks per mesh)."""
    cmd = [exe, "info"]
    for k, v in sets.items():
        cmd += ["--set", f"{k}={v}"]
    out = subprocess.run(cmd, capture_output=True, text=True).stdout
    for line in out.splitlines():
        if line.startswith("time scheme"):
            return line.split()[2]
    return None


def run_one(exe, out, name, sets, threads, report_only=False):
    folder = os.path.join(out, name)
    summary = os.path.join(folder, "summary.json")
    if os.path.exists(summary):
        return json.load(open(summary)), True
    if report_only:
        return None, True
    cmd = [exe, "run", "-o", folder, "--overwrite", "--threads", str(threads)]
    for k, v in sets.items():
        cmd += ["--set", f"{k}={v}"]
    with open(folder + ".log", "w") as log:
        code = subprocess.call(cmd, stdout=log, stderr=subprocess.STDOUT)
    if not os.path.exists(summary):
        return {"stop_reason": f"no summary (exit {code})"}, False
    return json.load(open(summary)), False


def outcome(s):
    r = s.get("stop_reason", "?")
    if r == "t_end" and s.get("steady"):
        return "steady"
    return r.split(":")[0]


def row_of(name, cfg, s):
    h = s.get("health", {})
    return dict(name=name, **cfg, outcome=outcome(s), stop_reason=s.get("stop_reason"), t=s.get("t"),
                D12=s.get("D12"), D13=s.get("D13"), volume_drift=s.get("volume_drift"),
                grid_oscillation_max=h.get("grid_oscillation_max"), facet_angle_max=h.get("facet_angle_max"),
                compressed_area_fraction_max=h.get("compressed_area_fraction_max"), min_tension=h.get("min_tension"),
                min_facet_angle=h.get("min_facet_angle"), max_stretch=h.get("max_stretch"),
                newton_per_eval_max=h.get("newton_per_eval_max"), mass_cg_per_eval_max=h.get("mass_cg_per_eval_max"),
                warnings=" ".join(sorted({w["condition"] for w in h.get("warnings", [])})),
                elements=s.get("elements"), scheme=s.get("scheme"), rhs_evaluations=s.get("rhs_evaluations"),
                wall_seconds=s.get("wall_seconds"))


def write_atomically(path, text):
    with open(path + ".tmp", "w", newline="") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


def write_tables(rows, out):
    keys = list(rows[0].keys())
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=keys)
    w.writeheader()
    w.writerows(rows)
    write_atomically(os.path.join(out, "results.csv"), buf.getvalue())
    cols = ["level", "wall", "law", "shape", "flow", "ca", "outcome", "t", "D12", "D13", "grid_oscillation_max",
            "facet_angle_max", "compressed_area_fraction_max", "min_facet_angle", "max_stretch", "rhs_evaluations",
            "wall_seconds"]
    md = "| " + " | ".join(cols) + " |\n|" + "---|" * len(cols) + "\n"
    for r in rows:
        md += "| " + " | ".join(f"{r[c]:.3g}" if isinstance(r[c], float) else str(r[c]) for c in cols) + " |\n"
    write_atomically(os.path.join(out, "results.md"), outcome_grid(rows) + "\n" + md)


LETTER = {"steady": "S", "t_end": "T", "mesh_scale_buckling": "B", "unresolved_folds": "F", "no_equilibrium": "N",
          "element_quality": "Q", "blow_up": "X", "solver_failure": "!", "no_progress": "P"}


def outcome_grid(rows):
    """One line per configuration, one column per Ca_s: the outcome's letter and the γ̇t it ended at."""
    cas = sorted({r["ca"] for r in rows})
    grid = {}
    for r in rows:
        key = (f"{r['level']}", r["wall"], r["law"], r["shape"], r["flow"].replace("planar_", ""), r["stops_on"])
        grid.setdefault(key, {})[r["ca"]] = f"{LETTER.get(r['outcome'], '?')} {r['t']:.2g}" if r["t"] is not None else "?"
    legend = ", ".join(f"{v} {k}" for k, v in LETTER.items())
    md = f"Outcome and γ̇t reached ({legend}; empty: not in the matrix or not run).\n\n"
    md += "| level | wall | law | shape | flow | stops on | " + " | ".join(f"Ca_s {c:g}" for c in cas) + " |\n"
    md += "|---" * (6 + len(cas)) + "|\n"
    for key, by_ca in grid.items():
        md += "| " + " | ".join(key) + " | " + " | ".join(by_ca.get(c, "") for c in cas) + " |\n"
    return md


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--matrix", choices=MATRICES, default="small")
    ap.add_argument("-o", "--out", required=True)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--exe", default=EXE, help="capsflow binary (default: build/bin/capsflow of this checkout)")
    ap.add_argument("--report-only", action="store_true", help="run nothing: tables and map from the finished runs")
    ap.add_argument("--scheme", default="auto", choices=["auto", "rkc", "rock4", "heun"],
                    help="time.scheme of every run (default: the default, auto)")
    ap.add_argument("--levels", default="", help="only these mesh levels, e.g. 3 or 3,4 (default: the matrix's)")
    ap.add_argument("--only-picked", default="", choices=["", "rkc", "rock4"],
                    help="only the runs for which the scheme (auto) picks this one, as `capsflow info` says")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    rows = []
    todo = list(runs(MATRICES[a.matrix], a.scheme))
    if a.levels:
        keep = {int(x) for x in a.levels.split(",")}
        todo = [r for r in todo if r[1]["level"] in keep]
    if a.only_picked:
        todo = [r for r in todo if picked_scheme(a.exe, r[2]) == a.only_picked]
        print(f"{len(todo)} runs for which the scheme picks {a.only_picked}", flush=True)
    start = time.time()
    for i, (name, cfg, sets) in enumerate(todo):
        s, cached = run_one(a.exe, a.out, name, sets, a.threads, a.report_only)
        if s is None:
            continue
        rows.append(row_of(name, cfg, s))
        write_tables(rows, a.out)  # after every run: a campaign cut short keeps its table
        el = time.time() - start
        cost = "cached" if cached else f"{rows[-1]['wall_seconds'] or 0:.0f} s"
        print(f"[{i + 1}/{len(todo)}] {name}: {rows[-1]['outcome']} at t = {rows[-1]['t']} ({cost}; elapsed {el:.0f} s)",
              flush=True)
    stability_map(rows, os.path.join(a.out, "stability_map.png"))


def stability_map(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    colors = {"t_end": "#2ca02c", "steady": "#1f77b4", "mesh_scale_buckling": "#ff7f0e", "unresolved_folds": "#bcbd22",
              "element_quality": "#9467bd", "no_equilibrium": "#8c564b", "blow_up": "#d62728",
              "solver_failure": "#e377c2", "no_progress": "#7f7f7f"}
    def config(r):
        return (f"L{r['level']}", r["wall"], r["law"], r["shape"], r["flow"]) + \
               (() if r.get("stops_on", "all") == "all" else (r["stops_on"],))
    configs = sorted({config(r) for r in rows})
    cas = sorted({r["ca"] for r in rows})
    fig, ax = plt.subplots(figsize=(7, 0.28 * len(configs) + 1.5))
    for y, c in enumerate(configs):
        for r in rows:
            if config(r) == c:
                ax.scatter(cas.index(r["ca"]), y, s=90, marker="s", color=colors.get(r["outcome"], "k"))
    ax.set_yticks(range(len(configs)))
    ax.set_yticklabels([" | ".join(c) for c in configs], fontsize=6)
    ax.set_xticks(range(len(cas)))
    ax.set_xticklabels([f"{c:g}" for c in cas])
    ax.set_xlabel("Ca_s")
    handles = [plt.Line2D([], [], marker="s", ls="", color=v, label=k) for k, v in colors.items()
               if any(r["outcome"] == k for r in rows)]
    ax.legend(handles=handles, fontsize=6, loc="upper left", bbox_to_anchor=(1, 1))
    fig.tight_layout()
    fig.savefig(path, dpi=150)


if __name__ == "__main__":
    sys.exit(main())
