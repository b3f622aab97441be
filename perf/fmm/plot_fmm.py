#!/usr/bin/python3
"""Plot fmm_bench JSON lines: Pareto fronts (time vs error), time vs N, crossover.

usage: /usr/bin/python3 plot_fmm.py [RESULTS_DIR]   (Debian python3-matplotlib; default: results/)
writes pareto.png, time_vs_n.png, crossover.png into perf/fmm/.
"""
import json
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
RES = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "results")

# PVFMM and FMM3D on this machine kind (the floors' peers; sphere surface, sources = targets, 2 threads)
PEERS = {
    "PVFMM": {1e4: [(0.04 + 0.19, 1.3e-5), (0.09 + 0.21, 2.2e-7)],
              1e5: [(0.14 + 0.95, 1.2e-5), (0.18 + 1.49, 1.6e-7), (0.49 + 2.29, 4.8e-10)],
              1e6: [(1.57 + 11.1, 1.8e-5), (1.93 + 19.6, 2.5e-7)]},
    "FMM3D": {1e4: [(0.23, 1.9e-7)], 1e5: [(3.94, 2.0e-7), (7.39, 1.7e-10)],
              1e6: [(29.8, 1.6e-4), (49.7, 3.5e-7)]},
}


def load(name):
    path = os.path.join(RES, name)
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [json.loads(l) for l in f if l.startswith("{")]


def pareto():
    rows = load("peers.jsonl")
    fig, axes = plt.subplots(1, 3, figsize=(13, 4), sharey=False)
    for ax, n in zip(axes, (1e4, 1e5, 1e6)):
        mine = sorted([r for r in rows if r["n"] == int(n)], key=lambda r: r["order"])
        if mine:
            ax.loglog([r["rel_l2_error"] for r in mine], [r["setup_s"] + r["eval_s"] for r in mine],
                      "o-", label="capsflow KIFMM")
            for r in mine:
                ax.annotate("p=%d" % r["order"], (r["rel_l2_error"], r["setup_s"] + r["eval_s"]),
                            fontsize=7, xytext=(3, 3), textcoords="offset points")
        for peer, mk in (("PVFMM", "s--"), ("FMM3D", "^:")):
            pts = PEERS[peer].get(n, [])
            if pts:
                ax.loglog([e for _, e in pts], [t for t, _ in pts], mk, label=peer)
        ax.set_title("sphere, N = %.0e, 2 threads" % n)
        ax.set_xlabel("relative L2 error")
        ax.invert_xaxis()
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("setup + evaluation [s]")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "pareto.png"), dpi=120)


def time_vs_n():
    rows = load("peers.jsonl") + load("crossover.jsonl")
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for p in sorted({r["order"] for r in rows}):
        pts = sorted({(r["n"], r["setup_s"] + r["eval_s"]) for r in rows if r["order"] == p})
        if len(pts) > 1:
            ax.loglog([n for n, _ in pts], [t for _, t in pts], "o-", label="FMM p=%d" % p)
    d = sorted({(r["n"], r["direct_s"]) for r in rows})
    ax.loglog([n for n, _ in d], [t for _, t in d], "k--", label="direct sum (extrapolated)")
    ax.set_xlabel("N (sources = targets, sphere surface)")
    ax.set_ylabel("seconds (setup + one evaluation)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "time_vs_n.png"), dpi=120)


def crossover():
    rows = load("crossover.jsonl")
    if not rows:
        return
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for tol in sorted({r["tol"] for r in rows}, reverse=True):
        pts = sorted([r for r in rows if r["tol"] == tol], key=lambda r: r["n"])
        ax.loglog([r["n"] for r in pts], [r["setup_s"] + r["eval_s"] for r in pts], "o-",
                  label="FMM tol %g (p=%d)" % (tol, pts[0]["order"]))
    d = sorted({(r["n"], r["direct_s"]) for r in rows})
    ax.loglog([n for n, _ in d], [t for _, t in d], "k--", label="direct sum")
    ax.set_xlabel("N")
    ax.set_ylabel("seconds")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "crossover.png"), dpi=120)


if __name__ == "__main__":
    pareto()
    time_vs_n()
    crossover()
