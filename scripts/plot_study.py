#!/usr/bin/python3
"""Figures of a convergence study (capsflow study, docs/scene-and-output.md §4).

    python3 scripts/plot_study.py STUDYDIR [--out STUDYDIR/figures] [--time final|T]

Reads STUDYDIR/study.json and writes into the figures folder:
  observables_vs_h.png   each observable against h (h = 2^-level, relative), one line per family,
                         the Richardson limit f* dashed where the family is asymptotic
  error_vs_h.png         |f - f*| against h on log axes, with the least-squares slope of the
                         levels shown (only asymptotic rows: others have no f*)
  error_vs_time.png      |f - f*| against the variant's wall time: the time-against-error front,
                         one curve per family
  cost_vs_n.png          seconds per right-hand-side evaluation by phase against the element count,
                         with the fitted exponent of each phase (cost growth)
Needs python3-matplotlib and python3-numpy (Debian packages; setup.sh installs them).
"""
import argparse
import json
import math
import os

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def slope(x, y):
    """Least-squares slope of log y against log x (None with fewer than two usable points)."""
    pts = [(math.log(a), math.log(b)) for a, b in zip(x, y) if a > 0 and b is not None and b > 0]
    if len(pts) < 2:
        return None
    lx, ly = np.array(pts).T
    return float(np.polyfit(lx, ly, 1)[0])


def rows_at(study, when):
    if when == "final":
        return study["final"]
    t = float(when)
    rows = [r for r in study["series"] if abs(r["t"] - t) <= 1e-9 * max(1.0, abs(t))]
    if not rows:
        raise SystemExit(f"no output time {t:g} common to the levels in study.json")
    return rows


def grid(n):
    cols = 4 if n > 6 else max(1, n)
    return math.ceil(n / cols), cols


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("studydir")
    p.add_argument("--out", default=None, help="figures folder (default STUDYDIR/figures)")
    p.add_argument("--time", default="final", help="'final' (default) or an output time common to all levels")
    a = p.parse_args()
    with open(os.path.join(a.studydir, "study.json")) as f:
        study = json.load(f)
    figs = a.out or os.path.join(a.studydir, "figures")
    os.makedirs(figs, exist_ok=True)
    rows = rows_at(study, a.time)
    observables = list(dict.fromkeys(r["observable"] for r in rows))
    families = list(dict.fromkeys(r["family"] for r in rows))
    colours = {f: plt.cm.tab10(i % 10) for i, f in enumerate(families)}
    wall = {}  # (family, level) -> wall seconds
    for v in study["variants"]:
        if v.get("state") == "finished":
            wall[(v["family"], v["level"])] = v["wall_seconds"]
    when = "at the end" if a.time == "final" else f"at $\\dot\\gamma t$ = {float(a.time):g}"

    # 1 observable against h, 2 |error| against h, 3 |error| against wall time
    nr, nc = grid(len(observables))
    figs_axes = [plt.subplots(nr, nc, figsize=(3.4 * nc, 2.8 * nr), squeeze=False) for _ in range(3)]
    for k, obs in enumerate(observables):
        axes = [fa[1][k // nc][k % nc] for fa in figs_axes]
        for r in (r for r in rows if r["observable"] == obs):
            fam, levels, c = r["family"], r["levels"], colours[r["family"]]
            h = [2.0 ** -l for l in levels]
            vals = [v for v in r["values"]]
            axes[0].plot(h, vals, "o-", color=c, label=fam)
            if r["extrapolated"] is not None:
                axes[0].axhline(r["extrapolated"], color=c, ls="--", lw=0.8)
            if r["status"] != "asymptotic":
                continue
            err = [abs(e) if e is not None else None for e in r["errors"]]
            s = slope(h, err)
            axes[1].loglog(h, err, "o-", color=c, label=f"{fam}: slope {s:.2f}" if s is not None else fam)
            t = [wall.get((fam, l)) for l in levels]
            pts = [(x, y) for x, y in zip(t, err) if x and y]
            if pts:
                axes[2].loglog(*zip(*pts), "o-", color=c, label=fam)
                for (x, y), l in zip(pts, levels):
                    axes[2].annotate(f"L{l}", (x, y), fontsize=6, xytext=(2, 2), textcoords="offset points")
        # Panels without an asymptotic family say why, instead of staying blank.
        skipped = [f"{r['family']}: {r['status']}" for r in rows if r["observable"] == obs and r["status"] != "asymptotic"]
        for ax in axes[1:]:
            if skipped and not ax.get_legend_handles_labels()[0]:
                ax.text(0.5, 0.5, "no order:\n" + "\n".join(skipped), ha="center", va="center", fontsize=7,
                        transform=ax.transAxes)
                ax.set_xticks([])
                ax.set_yticks([])
        axes[0].set_xscale("log")
        titles = [obs, f"|{obs} − {obs}*|", f"|{obs} − {obs}*|"]
        xlabels = ["h (relative: $2^{-level}$)", "h (relative: $2^{-level}$)", "wall time per variant [s]"]
        for ax, t, xl in zip(axes, titles, xlabels):
            ax.set_title(t, fontsize=9)
            ax.set_xlabel(xl, fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3, which="both")
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=6)
    names = ["observables_vs_h.png", "error_vs_h.png", "error_vs_time.png"]
    sups = [f"value per level {when}", f"error against the Richardson limit {when} (asymptotic rows only)",
            f"time against error {when}: one curve per family"]
    for (fig, axs), name, sup in zip(figs_axes, names, sups):
        for k in range(len(observables), nr * nc):
            axs[k // nc][k % nc].axis("off")
        fig.suptitle(sup, fontsize=10)
        fig.tight_layout()
        fig.savefig(os.path.join(figs, name), dpi=130)
        plt.close(fig)

    # 4 seconds per evaluation by phase against N, one panel per family
    fig, axs = plt.subplots(1, len(families), figsize=(4.5 * len(families), 3.8), squeeze=False)
    for ax, fam in zip(axs[0], families):
        vs = sorted((v for v in study["variants"] if v["family"] == fam and v.get("seconds_per_evaluation_by_phase")),
                    key=lambda v: v["elements"])
        if not vs:
            continue
        n = [v["elements"] for v in vs]
        phases = list(dict.fromkeys(k for v in vs for k in v["seconds_per_evaluation_by_phase"]))
        series = {"total": [v["seconds_per_evaluation"] for v in vs]}
        for ph in phases:
            series[ph] = [v["seconds_per_evaluation_by_phase"].get(ph) for v in vs]
        for name, y in series.items():
            if not any(val and val > 0 for val in y):
                continue
            s = slope(n, y)
            pts = [(x, val) for x, val in zip(n, y) if val and val > 0]
            ax.loglog(*zip(*pts), "o-" if name != "total" else "ks-", lw=2 if name == "total" else 1,
                      label=f"{name}: N^{s:.2f}" if s is not None else name)
        ax.set_title(fam, fontsize=9)
        ax.set_xlabel("elements N", fontsize=8)
        ax.set_ylabel("seconds per evaluation", fontsize=8)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=6)
    fig.suptitle("cost per right-hand-side evaluation by phase (fitted exponent)", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(figs, "cost_vs_n.png"), dpi=130)
    plt.close(fig)
    print(f"figures in {figs}: " + ", ".join(names + ["cost_vs_n.png"]))


if __name__ == "__main__":
    main()
