#!/bin/sh
# Reproduce perf/fmm/RESULTS.md. Usage: perf/fmm/run_fmm_bench.sh BUILD_DIR [OUT_DIR]
# BUILD_DIR configured with -DCAPSFLOW_NATIVE=ON -DCAPSFLOW_BENCHMARKS=ON, targets fmm_bench and
# direct_bench built. Writes JSON lines to OUT_DIR (default perf/fmm/results).
set -eu
B=${1:?build dir}
OUT=${2:-$(dirname "$0")/results}
mkdir -p "$OUT"
export CAPSFLOW_CACHE_DIR=${CAPSFLOW_CACHE_DIR:-$B/fmm-cache}
export OMP_WAIT_POLICY=passive
F="$B/perf/fmm/fmm_bench --threads 2"
# 1. direct-sum throughput
"$B/perf/fmm/direct_bench" --threads 2 --n 20000 --ntrg 20000 > "$OUT/direct.jsonl"
"$B/perf/fmm/direct_bench" --threads 1 --n 20000 --ntrg 10000 >> "$OUT/direct.jsonl"
# 2. peer table: sphere surface, sources = targets, orders around the peers' accuracies
: > "$OUT/peers.jsonl"
for n in 1e4 1e5; do for p in 4 6 7 8 9 10; do $F --dist sphere --n $n --order $p --reps 3 >> "$OUT/peers.jsonl"; done; done
for p in 6 7 8 9 10; do $F --dist sphere --n 1e6 --order $p --reps 3 >> "$OUT/peers.jsonl"; done
# 3. capsflow shapes: 6 Gauss-point sources per mesh node, targets = nodes (sources != targets)
: > "$OUT/capsflow.jsonl"
for nt in 2562 10242 40962 163842; do
  $F --dist sphere --n $((nt * 6)) --ntrg $nt --tol 1e-6 --reps 3 >> "$OUT/capsflow.jsonl"
done
# 4. distributions at N = 1e5, tolerance 1e-6
: > "$OUT/dists.jsonl"
for d in sphere spheroid cube clustered; do $F --dist $d --n 1e5 --tol 1e-6 --reps 3 >> "$OUT/dists.jsonl"; done
# 5. crossover: FMM (setup + one evaluation) against the direct sum, sources = targets
: > "$OUT/crossover.jsonl"
for tol in 1e-3 1e-6 1e-8; do for n in 4000 8000 16000 32000 64000; do
  $F --dist sphere --n $n --tol $tol --reps 3 --sample 2000 >> "$OUT/crossover.jsonl"
done; done
# 6. tight tolerances (the 1e-9 row against PVFMM m = 12 and FMM3D eps 1e-9), sphere, N = 1e5
: > "$OUT/tight.jsonl"
for p in 11 12 13; do $F --dist sphere --n 1e5 --order $p --reps 3 >> "$OUT/tight.jsonl"; done
# 7. several densities per call: one evaluate(f, u, 3) against 3 single calls
: > "$OUT/multi.jsonl"
for p in 7 10; do for n in 1e5 1e6; do $F --dist sphere --n $n --order $p --densities 3 --reps 3 >> "$OUT/multi.jsonl"; done; done
