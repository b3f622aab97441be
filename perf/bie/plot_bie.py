#!/usr/bin/python3
"""Time against error of one single-layer evaluation (bie_bench JSON lines), per surface geometry
and back end.

    build-perf/bin/bie_bench --levels 3,4,5,6 --backends direct,fmm --geometry flat,curved \\
        --tol 1e-3,1e-5 --repeat 5 --threads 2 > perf/bie/results.jsonl
    perf/bie/plot_bie.py perf/bie/results.jsonl perf/bie/time_vs_error.png
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

rows = [json.loads(l) for l in open(sys.argv[1]) if l.strip().startswith("{")]
fig, axes = plt.subplots(1, 3, figsize=(15, 4.4))
series = {}
for r in rows:
    be = r["backend"] if r["backend"] == "direct" else f"fmm tol {r['tol']:g}"
    series.setdefault(f"{r.get('geometry', 'flat')}, {be}", []).append(r)
errors = [("error_uniform_load", "uniform load → 2c/3"), ("error_rotation_load", "load ω×n → ω×x/3")]
for key, rs in sorted(series.items()):
    rs.sort(key=lambda r: r["elements"])
    style = "o-" if key.startswith("flat") else "s--"
    for ax, (field, _) in zip(axes, errors):
        ok = [r for r in rs if r.get(field) is not None]  # --uniform-only rows lack the rotation error
        ax.loglog([r[field] for r in ok], [r["eval_s"] for r in ok], style, label=key)
        for r in ok:
            ax.annotate(f"L{r['level']}", (r[field], r["eval_s"]), fontsize=7)
    axes[2].loglog([r["elements"] for r in rs], [r["eval_s"] for r in rs], style, label=key)
for ax, (_, title) in zip(axes, errors):
    ax.set_xlabel(f"max relative error, unit sphere: {title}")
    ax.set_ylabel("one evaluation [s] (median)")
    ax.set_title("time against error")
axes[2].set_xlabel("elements")
axes[2].set_ylabel("one evaluation [s] (median)")
axes[2].set_title("time against N")
for a in axes:
    a.grid(alpha=0.3, which="both")
    a.legend(fontsize=7)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=140)
