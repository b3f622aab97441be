#!/bin/sh
# The stresslet's hardest calibration case: random f with the outward normals of the sphere and
# spheroid (fmm_bench --density surface-random), error against order. N = 1e4 with 64 points per
# leaf (as order_sweep.sh) and N = 3000 with 48 (as the unit and Python tests), sources = targets
# and separate targets, seeds 1–3; all targets checked. The stresslet rows of
# fmm/include/capsflow/fmm/calibration.hpp take twice the worst of this and order_sweep.sh's cases.
# Usage: perf/fmm/order_sweep_surface_random.sh BUILD_DIR OUT.jsonl [ORDERS]   (~25 min on 2 cores)
set -eu
B=${1:?build dir}
OUT=${2:?output file}
ORDERS=${3:-"4 5 6 7 8 9 10 11 12 13 14"}
export CAPSFLOW_CACHE_DIR=${CAPSFLOW_CACHE_DIR:-$B/fmm-cache}
export OMP_WAIT_POLICY=passive
: > "$OUT"
for p in $ORDERS; do
  for d in sphere spheroid; do for seed in 1 2 3; do
    F="$B/perf/fmm/fmm_bench --kernel stresslet --density surface-random --threads 2 --reps 1 --dist $d --order $p --seed $seed"
    $F --n 1e4 --leaf 64 --sample 10000 >> "$OUT"
    $F --n 1e4 --leaf 64 --sample 10000 --ntrg 3000 >> "$OUT"
    $F --n 3000 --leaf 48 --sample 3000 >> "$OUT"
    $F --n 3000 --leaf 48 --sample 3000 --ntrg 1000 >> "$OUT"
  done; done
done
