#!/usr/bin/python3
"""Time against error of one single-layer evaluation (bie_bench JSON lines) per back end.

    build-perf/bin/bie_bench --levels 3,4,5,6 --backends direct,fmm --tol 1e-3,1e-6 > perf/bie/results.jsonl
    perf/bie/plot_bie.py perf/bie/results.jsonl perf/bie/time_vs_error.png
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

rows = [json.loads(l) for l in open(sys.argv[1]) if l.strip().startswith("{")]
fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
series = {}
for r in rows:
    key = r["backend"] if r["backend"] == "direct" else f"fmm tol {r['tol']:g}"
    series.setdefault(key, []).append(r)
for key, rs in sorted(series.items()):
    rs.sort(key=lambda r: r["elements"])
    a1.loglog([r["error_uniform_load"] for r in rs], [r["eval_s"] for r in rs], "o-", label=key)
    for r in rs:
        a1.annotate(f"L{r['level']}", (r["error_uniform_load"], r["eval_s"]), fontsize=7)
    a2.loglog([r["elements"] for r in rs], [r["eval_s"] for r in rs], "o-", label=key)
a1.set_xlabel("error (uniform load on the unit sphere, max relative)")
a1.set_ylabel("one evaluation [s] (median)")
a1.set_title("time against error")
a2.set_xlabel("elements")
a2.set_ylabel("one evaluation [s] (median)")
a2.set_title("time against N")
for a in (a1, a2):
    a.grid(alpha=0.3, which="both")
    a.legend(fontsize=8)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=140)
