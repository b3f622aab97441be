#!/usr/bin/env bash
# leaf_bie.sh — points per leaf against FMM time in the boundary integral's configuration:
# sources on the sphere's edge midpoints (3 per node) and the nodes as separate targets, at the
# sizes of icosahedron levels 5, 6 and 7 (20 480, 81 920, 327 680 elements), plus sources =
# targets at N = 1e5 (the library's own calibration case). Random points on the sphere with the
# same counts (fmm_bench --dist sphere). Run on a quiet machine; one JSON line per run.
#   perf/fmm/leaf_bie.sh BUILD OUT [ORDERS] [KERNEL] [LEAVES]
set -euo pipefail
build=${1:?build dir}; out=${2:?output jsonl}
orders=${3:-"6 7 8 9 10 12"}; kernel=${4:-stokeslet}; leaves=${5:-"400 600 800 1000 1300 1600"}
bench="$build/perf/fmm/fmm_bench"
for o in $orders; do
  for cfg in 30720:10242 122880:40962 491520:163842 100000:0; do
    n=${cfg%:*}; t=${cfg#*:}
    for leaf in $leaves; do
      OMP_NUM_THREADS=2 "$bench" --dist sphere --n "$n" --ntrg "$t" --order "$o" --leaf "$leaf" \
        --threads 2 --reps 5 --sample 300 --kernel "$kernel" | tail -1 >> "$out"
    done
  done
done
