#!/usr/bin/python3
"""Markdown tables for RESULTS.md's stresslet section from perf/fmm/stresslet_bench.sh output.

usage: /usr/bin/python3 stresslet_tables.py [RESULTS_DIR]   (default: results/stresslet)
Ratios are stresslet / Stokeslet, from lines measured side by side in one fmm_bench process.
"""
import os
import sys

from make_tables import HERE, crossover_table, load

RES = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "results", "stresslet")


def total(r):
    return r["setup_s"] + r["eval_s"]


def pairs(rows):
    """(stokeslet, stresslet) lines of one fmm_bench --kernel stokeslet,stresslet call (consecutive)."""
    return [(a, b) for a, b in zip(rows, rows[1:])
            if a["kernel"] == "stokeslet" and b["kernel"] == "stresslet"
            and (a["dist"], a["n"], a["ntrg"]) == (b["dist"], b["n"], b["ntrg"])]


def floor_table(rows):
    print("\n### Floor: stresslet against Stokeslet at tolerance 1e-6 (setup + evaluation, seconds)\n")
    print("| dist | N src | N trg | Stokeslet p / err / s | stresslet p / err / s | ratio (setup+eval) | ratio (eval) | floor ≤ 2 |")
    print("|---|---|---|---|---|---|---|---|")
    for a, b in pairs(rows):
        ok = total(b) <= 2 * total(a) and max(a["rel_l2_error"], b["rel_l2_error"]) <= 1e-6
        print("| %s | %d | %d | %d / %.1e / %.3f | %d / %.1e / %.3f | %.2f | %.2f | %s |" % (
            a["dist"], a["n"], a["ntrg"], a["order"], a["rel_l2_error"], total(a), b["order"], b["rel_l2_error"],
            total(b), total(b) / total(a), b["eval_s"] / a["eval_s"], "yes" if ok else "**no**"))
    print("\nPhases of the stresslet / Stokeslet evaluation (seconds):\n")
    print("| dist | N src | P2P | M2L | P2M | M2M | L2L | L2P | X | other |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for a, b in pairs(rows):
        ph = ["p2p", "m2l", "p2m", "m2m", "l2l", "l2p", "x", "other"]
        print("| %s | %d | %s |" % (a["dist"], a["n"], " | ".join(
            "%.3f / %.3f" % (b["phases"][k], a["phases"][k]) for k in ph)))


def pareto_table(rows):
    print("\n### Time against error, N = 1e5 (setup + evaluation, seconds)\n")
    print("| dist | p | Stokeslet err | Stokeslet s | stresslet err | stresslet s | ratio |")
    print("|---|---|---|---|---|---|---|")
    for a, b in pairs(rows):
        print("| %s | %d | %.1e | %.3f | %.1e | %.3f | %.2f |" % (
            a["dist"], a["order"], a["rel_l2_error"], total(a), b["rel_l2_error"], total(b), total(b) / total(a)))
    print("\nEqual error: the fastest run of each kernel whose error is at most E (same distribution):\n")
    print("| dist | E | Stokeslet p / s | stresslet p / s | ratio |")
    print("|---|---|---|---|---|")
    for dist in sorted({r["dist"] for r in rows}):
        for e in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9):
            best = {}
            for r in rows:
                if r["dist"] == dist and r["rel_l2_error"] <= e:
                    k = r["kernel"]
                    if k not in best or total(r) < total(best[k]):
                        best[k] = r
            if "stokeslet" in best and "stresslet" in best:
                a, b = best["stokeslet"], best["stresslet"]
                print("| %s | %g | %d / %.3f | %d / %.3f | %.2f |" % (
                    dist, e, a["order"], total(a), b["order"], total(b), total(b) / total(a)))


def leaf_table(rows):
    print("\n### Stresslet leaf size (sphere, setup + evaluation, seconds; best per row group in bold)\n")
    print("| N | tol | p | leaf | eval s | setup+eval s | err |")
    print("|---|---|---|---|---|---|---|")
    groups = {}
    for r in rows:
        groups.setdefault((r["n"], r["tol"]), []).append(r)
    for (n, tol), rs in groups.items():
        best = min(rs, key=total)
        for r in rs:
            mark = "**" if r is best else ""
            print("| %d | %g | %d | %s%d%s | %.3f | %.3f | %.1e |" % (
                n, tol, r["order"], mark, r["leaf"], mark, r["eval_s"], total(r), r["rel_l2_error"]))


if __name__ == "__main__":
    for r in load("direct.jsonl", RES):
        print("direct_sum %s: %d x %d, %d threads: %.3f s, %.2f G pairs/s (%s)" % (
            r["kernel"], r["ntrg"], r["n"], r["threads"], r["seconds"], r["pairs_per_s"] / 1e9, r["isa"]))
    floor_table(load("floor.jsonl", RES))
    pareto_table(load("pareto.jsonl", RES))
    leaf_table(load("leaf.jsonl", RES))
    print("\n### Stresslet crossover (sphere, sources = targets)")
    crossover_table(load("crossover.jsonl", RES))
