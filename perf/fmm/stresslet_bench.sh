#!/bin/sh
# The stresslet (double-layer) FMM against the Stokeslet FMM, side by side in one process per case
# (perf/fmm/RESULTS.md, "Stresslet"). Usage: perf/fmm/stresslet_bench.sh BUILD_DIR [OUT_DIR]
# BUILD_DIR configured with -DCAPSFLOW_NATIVE=ON -DCAPSFLOW_BENCHMARKS=ON, targets fmm_bench and
# direct_bench built. Writes JSON lines to OUT_DIR (default perf/fmm/results/stresslet); tables:
# /usr/bin/python3 perf/fmm/stresslet_tables.py OUT_DIR. About 12 minutes on a quiet machine.
set -eu
B=${1:?build dir}
OUT=${2:-$(dirname "$0")/results/stresslet}
mkdir -p "$OUT"
export CAPSFLOW_CACHE_DIR=${CAPSFLOW_CACHE_DIR:-$B/fmm-cache}
export OMP_WAIT_POLICY=passive
F="$B/perf/fmm/fmm_bench --threads 2"
# 1. direct-sum throughput of both kernels (the P2P cost per pair)
: > "$OUT/direct.jsonl"
for k in stokeslet stresslet; do
  "$B/perf/fmm/direct_bench" --threads 2 --n 20000 --ntrg 20000 --kernel $k >> "$OUT/direct.jsonl"
done
# 2. the stresslet's floor (≤ 2× the Stokeslet): N = 1e5, tolerance 1e-6, each kernel at its calibrated order, every
#    distribution; then N = 1e6 and capsule shapes (6 Gauss-point sources per node, sources != targets)
: > "$OUT/floor.jsonl"
for d in sphere spheroid cube clustered; do
  $F --dist $d --n 1e5 --tol 1e-6 --reps 5 --kernel stokeslet,stresslet >> "$OUT/floor.jsonl"
done
$F --dist sphere --n 1e6 --tol 1e-6 --reps 3 --kernel stokeslet,stresslet >> "$OUT/floor.jsonl"
for nt in 10242 40962 163842; do
  $F --dist sphere --n $((nt * 6)) --ntrg $nt --tol 1e-6 --reps 3 --kernel stokeslet,stresslet >> "$OUT/floor.jsonl"
done
# 3. time against error (equal-error ratios), N = 1e5, sphere and clustered, by order
: > "$OUT/pareto.jsonl"
for d in sphere clustered; do for p in 4 5 6 7 8 9 10 11 12; do
  $F --dist $d --n 1e5 --order $p --reps 3 --kernel stokeslet,stresslet >> "$OUT/pareto.jsonl"
done; done
# 4. leaf size of the stresslet at the orders of tolerances 1e-3, 1e-6 and 1e-8 (calibration.hpp's
#    leaf_size column; the Stokeslet's was tuned the same way), N = 1e5 and 1e6, sphere
: > "$OUT/leaf.jsonl"
for tol in 1e-3 1e-6 1e-8; do for leaf in 200 300 400 500 600 800; do
  $F --dist sphere --n 1e5 --tol $tol --leaf $leaf --reps 3 --kernel stresslet >> "$OUT/leaf.jsonl"
done; done
for leaf in 300 400 500 600 800; do
  $F --dist sphere --n 1e6 --tol 1e-6 --leaf $leaf --reps 3 --kernel stresslet >> "$OUT/leaf.jsonl"
done
# 5. crossover of the stresslet FMM (setup + one evaluation) against its direct sum
: > "$OUT/crossover.jsonl"
for tol in 1e-3 1e-6 1e-8; do for n in 4000 8000 16000 32000 64000; do
  $F --dist sphere --n $n --tol $tol --reps 3 --sample 2000 --kernel stresslet >> "$OUT/crossover.jsonl"
done; done
