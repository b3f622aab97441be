#!/usr/bin/env python3
"""Where the single layer's FMM becomes faster than its direct far field, per tolerance.

Reads bie_bench JSON lines (perf/bie/crossover.sh) and, for each tolerance, takes the far-field
seconds of one evaluation ("far_s": the direct sum, or the FMM's set-up and evaluation; the near
field is the same for both) at every size. The direct sum costs a·n_src·n_trg (a: the median over
sizes); the FMM's time is interpolated log-log between sizes. The crossover c is sqrt(n_src·n_trg)
where the two meet: backend "auto" takes direct while n_src·n_trg < c².
Prints one row per tolerance, ready for the crossover table of src/bie/backend_choice.cpp."""
import json
import math
import sys
from collections import defaultdict


def main(path):
    rows = [json.loads(l) for l in open(path) if l.strip().startswith("{")]
    by_tol = defaultdict(lambda: {"direct": [], "fmm": []})
    for r in rows:
        by_tol[r["tol"]][r["backend"]].append((r["sources"] * r["nodes"], r["far_s"], r.get("order", 0)))
    print("tolerance  FMM order  direct a (ns/pair)  crossover c = sqrt(n_src n_trg)  (sizes: product, direct s, fmm s)")
    for tol in sorted(by_tol, reverse=True):
        d = sorted(by_tol[tol]["direct"])
        f = sorted(by_tol[tol]["fmm"])
        if not d or not f:
            continue
        a = sorted(t / p for p, t, _ in d)[len(d) // 2]
        c = None
        for (p0, t0, _), (p1, t1, _) in zip(f, f[1:]):
            g0, g1 = t0 - a * p0, t1 - a * p1  # FMM minus direct; crossing where it changes sign
            if g0 > 0 >= g1:
                # log-log interpolation of the FMM time, linear direct time
                lo, hi = math.log(p0), math.log(p1)
                for _ in range(60):
                    mid = 0.5 * (lo + hi)
                    tf = math.exp(math.log(t0) + (mid - math.log(p0)) * (math.log(t1) - math.log(t0)) / (math.log(p1) - math.log(p0)))
                    if tf > a * math.exp(mid):
                        lo = mid
                    else:
                        hi = mid
                c = math.sqrt(math.exp(0.5 * (lo + hi)))
                break
        if c is None:
            c_txt = "direct wins at every size" if all(t > a * p for p, t, _ in f) else "FMM wins at every size"
        else:
            c_txt = f"{c:,.0f}"
        sizes = "; ".join(f"{p:.3g}: {a * p:.3g} / {t:.3g}" for p, t, _ in f)
        print(f"{tol:9.0e}  {f[0][2]:9d}  {a * 1e9:18.3f}  {c_txt:>30}  ({sizes})")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "perf/bie/crossover.jsonl")
