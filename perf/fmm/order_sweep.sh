#!/bin/sh
# Error against order: every distribution, sources = targets and 3000 separate targets, N = 1e4,
# 64 points per leaf, all targets checked. Usage: perf/fmm/order_sweep.sh BUILD_DIR OUT.jsonl [ORDERS [KERNEL]]
# (the calibration tables in fmm/include/capsflow/fmm/calibration.hpp are read off this output;
# KERNEL: stokeslet (default) or stresslet, which adds 4 cases: a smooth double layer on the sphere
# and spheroid, fmm_bench --density surface; SURFACE_ONLY=1 runs only those).
set -eu
B=${1:?build dir}
OUT=${2:?output file}
ORDERS=${3:-"8 9 10 11 12 13 14"}
KERNEL=${4:-stokeslet}
export CAPSFLOW_CACHE_DIR=${CAPSFLOW_CACHE_DIR:-$B/fmm-cache}
export OMP_WAIT_POLICY=passive
F="$B/perf/fmm/fmm_bench --threads 2 --reps 1 --n 1e4 --leaf 64 --sample 10000 --kernel $KERNEL"
: > "$OUT"
for p in $ORDERS; do
  if [ "${SURFACE_ONLY:-0}" != 1 ]; then for d in sphere spheroid cube clustered; do
    $F --dist $d --order $p >> "$OUT"
    $F --dist $d --order $p --ntrg 3000 >> "$OUT"
  done; fi
  if [ "$KERNEL" = stresslet ]; then for d in sphere spheroid; do
    $F --dist $d --order $p --density surface >> "$OUT"
    $F --dist $d --order $p --density surface --ntrg 3000 >> "$OUT"
  done; fi
done
