#!/usr/bin/env bash
# compare.sh N DIST — PVFMM (m = 4 6 8 10 12) against capsflow's fmm_bench (--tol 1e-3 .. 1e-10),
# Stokeslet, sources = targets, on the same points, same thread count; prints a table of
# setup + evaluation time against the measured relative L2 error (1000 random targets, direct sum).
#
#   DIST: sphere (unit sphere surface) | cube (uniform in [-1,1]^3) | spheroid | clustered
#   env:  PVFMM_BUILD  the BUILD_DIR given to build_pvfmm.sh   (default /tmp/pvfmm-build)
#         CAPSFLOW_BUILD  capsflow's perf build                   (default <repo>/build-perf)
#         OUT          where points and raw JSON lines go        (default /tmp/peers-results)
#         THREADS (2)  REPS (3, median)  ORDERS ("4 6 8 10 12")  TOLS ("1e-3 ... 1e-10")
#         WAIT_POLICY (passive: OMP_WAIT_POLICY for both codes; empty = the OpenMP runtime's
#         default, which on a machine busy with other work made PVFMM's 2-thread setup ~100x slower)
#         LEAF (600, PVFMM's max_pts)  NICE (0; 19 to yield to other work — on a busy machine
#         that distorts 2-thread timings badly, see README.md)
# The points are those fmm_bench --dist DIST --n N --seed 1 makes itself (gen_points.cpp),
# written once to $OUT/points-DIST-N.txt and read by both codes (fmm_bench --input).
set -euo pipefail
if [ $# -ne 2 ]; then echo "usage: $0 N DIST" >&2; exit 2; fi
N=$1; DIST=$2
HERE=$(cd "$(dirname "$0")" && pwd); ROOT=$(cd "$HERE/../.." && pwd)
PVFMM_BUILD=${PVFMM_BUILD:-/tmp/pvfmm-build}
CAPSFLOW_BUILD=${CAPSFLOW_BUILD:-$ROOT/build-perf}
OUT=${OUT:-/tmp/peers-results}
THREADS=${THREADS:-2}; REPS=${REPS:-3}; LEAF=${LEAF:-600}; NICE=${NICE:-0}
ORDERS=${ORDERS:-"4 6 8 10 12"}
TOLS=${TOLS:-"1e-3 1e-4 1e-5 1e-6 1e-7 1e-8 1e-9 1e-10"}
PV="$PVFMM_BUILD/pvfmm_stokes_bench"; FB="$CAPSFLOW_BUILD/perf/fmm/fmm_bench"
[ -x "$PV" ] || { echo "compare.sh: $PV missing: run build_pvfmm.sh first" >&2; exit 2; }
if [ ! -x "$FB" ]; then cmake --build "$CAPSFLOW_BUILD" --target fmm_bench -j1; fi
mkdir -p "$OUT" "$PVFMM_BUILD/precomp"
GEN="$OUT/gen_points"
if [ ! -x "$GEN" ] || [ "$HERE/gen_points.cpp" -nt "$GEN" ]; then
  g++ -std=c++17 -O2 -I"$ROOT/tests/fmm" "$HERE/gen_points.cpp" -o "$GEN"
fi
PTS="$OUT/points-$DIST-$N.txt"
[ -s "$PTS" ] || "$GEN" "$DIST" "$N" 1 "$PTS"
LOG="$OUT/compare-$DIST-$N.jsonl"; : > "$LOG"
export OMP_NUM_THREADS=$THREADS PVFMM_DIR="$PVFMM_BUILD/precomp"
WAIT_POLICY=${WAIT_POLICY-passive}
if [ -n "$WAIT_POLICY" ]; then export OMP_WAIT_POLICY=$WAIT_POLICY; else unset OMP_WAIT_POLICY; fi
for m in $ORDERS; do   # PVFMM caches its operators in $PVFMM_DIR (init_s, not counted in the time)
  nice -n "$NICE" "$PV" "$PTS" "$m" --leaf "$LEAF" --reps "$REPS" | tee -a "$LOG"
done
for t in $TOLS; do
  nice -n "$NICE" "$FB" --input "$PTS" --tol "$t" --threads "$THREADS" --reps "$REPS" \
    | sed "s/^{/{\"code\":\"capsflow\",\"input_dist\":\"$DIST\",/" | tee -a "$LOG"
done
python3 - "$LOG" "$N" "$DIST" "$THREADS" <<'PY'
import json, sys
log, n, dist, thr = sys.argv[1:]
rows = [json.loads(l) for l in open(log) if l.startswith("{")]
import os
wp = os.environ.get("OMP_WAIT_POLICY", "default")
print(f"\nStokeslet, N = {n}, {dist}, sources = targets, {thr} threads, OMP_WAIT_POLICY={wp} "
      "(median of reps; error: rel. L2 on 1000 targets)")
print("| code | parameter | setup s | eval s | setup + eval s | rel L2 error |")
print("|---|---|---|---|---|---|")
for r in rows:
    if r.get("code") == "pvfmm":
        par = f"m={r['m']} leaf={r['leaf']}"
    else:
        par = f"tol={r['tol']:g} (p={r['order']} leaf={r['leaf']})"
    print(f"| {r.get('code')} | {par} | {r['setup_s']:.3f} | {r['eval_s']:.3f} | "
          f"{r['setup_s'] + r['eval_s']:.3f} | {r['rel_l2_error']:.1e} |")
PY
