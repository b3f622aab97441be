#!/bin/sh
# Error against order: every distribution, sources = targets and 3000 separate targets, N = 1e4,
# 64 points per leaf, all targets checked. Usage: perf/fmm/order_sweep.sh BUILD_DIR OUT.jsonl [ORDERS]
# (the calibration table in fmm/include/capsflow/fmm/calibration.hpp is read off this output).
set -eu
B=${1:?build dir}
OUT=${2:?output file}
ORDERS=${3:-"8 9 10 11 12 13 14"}
export CAPSFLOW_CACHE_DIR=${CAPSFLOW_CACHE_DIR:-$B/fmm-cache}
export OMP_WAIT_POLICY=passive
F="$B/perf/fmm/fmm_bench --threads 2 --reps 1 --n 1e4 --leaf 64 --sample 10000"
: > "$OUT"
for p in $ORDERS; do for d in sphere spheroid cube clustered; do
  $F --dist $d --order $p >> "$OUT"
  $F --dist $d --order $p --ntrg 3000 >> "$OUT"
done; done
