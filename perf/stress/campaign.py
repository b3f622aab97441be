#!/usr/bin/python3
"""Stress campaign (issue 12): run capsflow over a matrix of capillary numbers, laws, walls, shapes
and flows, and record how each run ends, what the health monitors saw and what it cost.

    perf/stress/campaign.py --matrix small -o stress-out        # the matrix of perf/RESULTS.md §7
    perf/stress/campaign.py --matrix full  -o stress-out        # the issue's full sweep (hours)

Every run is an ordinary `capsflow run` in OUT/<name>/ with `time.stop_on` set to every health
condition, so a run ends at the first sign of trouble with a named stop_reason. Finished runs are
skipped when the campaign is started again. Writes OUT/results.csv, OUT/results.md and
OUT/stability_map.png (outcome against Ca_s, one row per configuration).
"""
import argparse
import csv
import itertools
import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
EXE = os.path.join(HERE, "..", "..", "build", "bin", "capsflow")
CONDITIONS = ["mesh_scale_buckling", "unresolved_folds", "element_quality", "no_equilibrium"]

MATRICES = {
    # 1280 elements, to γ̇t = 3: a strain-softening and a strain-hardening law, both wall families,
    # both flows, two shapes, Ca_s over four decades (48 runs, ≈ 15 min on 2 cores).
    "small": dict(ca=[1e-3, 0.1, 10.0], level=[3], t_end=3.0,
                  walls=[("membrane", None), ("gsmb", 0.03)],
                  laws=[("nh", {}), ("skalak", {"wall.skalak_c": 10})],
                  shapes=[("sphere", 1.0), ("spheroid", 2.0)], flows=["simple_shear", "planar_hyperbolic"]),
    # The sweep: 1280 and 5120 elements, GSMB α = 1–20 %, a/b up to 4, to γ̇t = 10.
    "full": dict(ca=[1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3, 1.0, 3.0, 10.0], level=[3, 4], t_end=10.0,
                 walls=[("membrane", None), ("gsmb", 0.01), ("gsmb", 0.03), ("gsmb", 0.1), ("gsmb", 0.2)],
                 laws=[("nh", {}), ("gh", {}), ("skalak", {"wall.skalak_c": 1}), ("skalak", {"wall.skalak_c": 10})],
                 shapes=[("sphere", 1.0), ("spheroid", 1.4), ("spheroid", 2.0), ("spheroid", 4.0)],
                 flows=["simple_shear", "planar_hyperbolic"]),
}


def runs(m):
    for ca, level, (wall, alpha), (law, extra), (shape, aspect), flow in itertools.product(
            m["ca"], m["level"], m["walls"], m["laws"], m["shapes"], m["flows"]):
        name = f"L{level}_{wall}{'' if alpha is None else f'{alpha:g}'}_{law}{''.join(f'{v:g}' for v in extra.values())}" \
               f"_{shape}{aspect:g}_{flow}_ca{ca:g}"
        sets = {"mesh.level": level, "mesh.shape": shape, "wall.model": wall, "wall.law": law, "flow.type": flow,
                "flow.ca_s": ca, "time.t_end": m["t_end"], "output.every": 0.1, "output.checkpoint_every": 1.0,
                "time.stop_on": "[" + ",".join(f'"{c}"' for c in CONDITIONS) + "]",
                # RKC for every wall: at Ca_s = 1e-3 Heun's step is 100× shorter than at 0.1.
                "time.scheme": "rkc"}
        if shape == "spheroid":
            sets["mesh.aspect"] = aspect
        if alpha is not None:
            sets["wall.thickness"] = alpha
        sets.update(extra)
        yield name, dict(ca=ca, level=level, wall=wall if alpha is None else f"gsmb {alpha:g}", law=law + "".join(
            f" C={v:g}" for v in extra.values()), shape=f"{shape} {aspect:g}", flow=flow), sets


def run_one(out, name, sets, threads):
    folder = os.path.join(out, name)
    summary = os.path.join(folder, "summary.json")
    if os.path.exists(summary):
        return json.load(open(summary)), True
    cmd = [EXE, "run", "-o", folder, "--overwrite", "--threads", str(threads)]
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


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--matrix", choices=MATRICES, default="small")
    ap.add_argument("-o", "--out", required=True)
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    rows = []
    todo = list(runs(MATRICES[a.matrix]))
    start = time.time()
    for i, (name, cfg, sets) in enumerate(todo):
        s, cached = run_one(a.out, name, sets, a.threads)
        h = s.get("health", {})
        warn = sorted({w["condition"] for w in h.get("warnings", [])})
        row = dict(name=name, **cfg, outcome=outcome(s), t=s.get("t"), D12=s.get("D12"), D13=s.get("D13"),
                   volume_drift=s.get("volume_drift"), grid_oscillation_max=h.get("grid_oscillation_max"),
                   min_facet_angle=h.get("min_facet_angle"), max_stretch=h.get("max_stretch"),
                   warnings=" ".join(warn), wall_seconds=s.get("wall_seconds"), scheme=s.get("scheme"),
                   rhs_evaluations=s.get("rhs_evaluations"))
        rows.append(row)
        el = time.time() - start
        cost = "cached" if cached else f"{row['wall_seconds'] or 0:.0f} s"
        print(f"[{i + 1}/{len(todo)}] {name}: {row['outcome']} at t = {row['t']} ({cost}; elapsed {el:.0f} s)", flush=True)
    keys = list(rows[0].keys())
    with open(os.path.join(a.out, "results.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(a.out, "results.md"), "w") as f:
        cols = ["wall", "law", "shape", "flow", "ca", "outcome", "t", "D12", "D13", "grid_oscillation_max",
                "min_facet_angle", "max_stretch", "wall_seconds"]
        f.write("| " + " | ".join(cols) + " |\n|" + "---|" * len(cols) + "\n")
        for r in rows:
            f.write("| " + " | ".join(f"{r[c]:.3g}" if isinstance(r[c], float) else str(r[c]) for c in cols) + " |\n")
    stability_map(rows, os.path.join(a.out, "stability_map.png"))


def stability_map(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    colors = {"t_end": "#2ca02c", "steady": "#1f77b4", "mesh_scale_buckling": "#ff7f0e", "unresolved_folds": "#bcbd22",
              "element_quality": "#9467bd", "no_equilibrium": "#8c564b", "blow_up": "#d62728",
              "solver_failure": "#e377c2", "no_progress": "#7f7f7f"}
    configs = sorted({(r["wall"], r["law"], r["shape"], r["flow"]) for r in rows})
    cas = sorted({r["ca"] for r in rows})
    fig, ax = plt.subplots(figsize=(7, 0.28 * len(configs) + 1.5))
    for y, c in enumerate(configs):
        for r in rows:
            if (r["wall"], r["law"], r["shape"], r["flow"]) == c:
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
