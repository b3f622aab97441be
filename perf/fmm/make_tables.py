#!/usr/bin/python3
"""Markdown tables for RESULTS.md from the fmm_bench JSON lines in results/.

usage: /usr/bin/python3 make_tables.py [RESULTS_DIR]; load() and crossover_table() also serve
stresslet_tables.py.
"""
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def load(name, res=None):
    p = os.path.join(res or RES, name)
    return [json.loads(l) for l in open(p) if l.startswith("{")] if os.path.exists(p) else []


def fmm_table(rows, title):
    print("\n" + title + "\n")
    print("| N src | N trg | p | leaf | setup s | eval s | setup+eval s | rel L2 err | max rel err | direct s | P2P | M2L | other |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        ph = r["phases"]
        other = sum(v for k, v in ph.items() if k not in ("p2p", "m2l", "m2l_fft", "m2l_hadamard"))
        print("| %d | %d | %d | %d | %.3f | %.3f | %.3f | %.1e | %.1e | %.2f | %.2f | %.2f | %.2f |" % (
            r["n"], r["ntrg"], r["order"], r["leaf"], r["setup_s"], r["eval_s"], r["setup_s"] + r["eval_s"],
            r["rel_l2_error"], r["max_rel_error"], r["direct_s"], ph["p2p"], ph["m2l"], other))


def crossover_table(rows):
    """N at which FMM setup + one evaluation becomes faster than the direct sum, per tolerance."""
    print("\n| tol | p | crossover N (FMM setup + 1 eval < direct) |\n|---|---|---|")
    for tol in sorted({r["tol"] for r in rows}, reverse=True):
        pts = sorted([r for r in rows if r["tol"] == tol], key=lambda r: r["n"])
        cross = None
        for a, b in zip(pts, pts[1:]):
            fa, fb = a["setup_s"] + a["eval_s"] - a["direct_s"], b["setup_s"] + b["eval_s"] - b["direct_s"]
            if fa > 0 >= fb:
                # log-log interpolation of the sign change
                la, lb = math.log(a["n"]), math.log(b["n"])
                ra = math.log((a["setup_s"] + a["eval_s"]) / a["direct_s"])
                rb = math.log((b["setup_s"] + b["eval_s"]) / b["direct_s"])
                cross = math.exp(la + (lb - la) * ra / (ra - rb))
                break
        if cross is None and pts and pts[0]["setup_s"] + pts[0]["eval_s"] < pts[0]["direct_s"]:
            cross = "< %d" % pts[0]["n"]
        print("| %g | %d | %s |" % (tol, pts[0]["order"], ("%.0f" % cross) if isinstance(cross, float) else cross))


if __name__ == "__main__":
    RES = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "results")
    for r in load("direct.jsonl"):
        print("direct_sum: %d x %d, %d threads: %.3f s, %.2f G pairs/s (%s)" % (
            r["ntrg"], r["n"], r["threads"], r["seconds"], r["pairs_per_s"] / 1e9, r["isa"]))
    fmm_table(load("peers.jsonl"), "### Sphere surface, sources = targets (peer comparison)")
    fmm_table(load("capsflow.jsonl"), "### capsflow shapes: 6 sources per target, sources != targets, tol 1e-6")
    fmm_table(load("dists.jsonl"), "### Distributions, N = 1e5, tol 1e-6")
    rows = load("crossover.jsonl")
    fmm_table(rows, "### Crossover runs (sphere, sources = targets)")
    crossover_table(rows)
