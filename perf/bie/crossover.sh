#!/usr/bin/env bash
# The FMM/direct crossover of the single layer (fluid.backend = "auto", src/bie/backend_choice.cpp):
# one evaluation timed with each back end at every calibrated tolerance, on spheres whose sizes
# bracket the crossover (icosphere levels 4, 5 and octahedron spheres of levels 5, 6: 2562, 4098,
# 10 242 and 16 386 nodes with 3 edge-midpoint sources per node), then crossover.py finds where the
# two times meet. Needs a quiet machine: it times. ~10 min on 2 cores.
#   perf/bie/crossover.sh [build-perf] [out.jsonl]
set -euo pipefail
build=${1:-build-perf}
out=${2:-perf/bie/crossover.jsonl}
here=$(cd "$(dirname "$0")" && pwd)
: > "$out"
for base_levels in "icosahedron 4,5" "octahedron 5,6"; do
  set -- $base_levels
  "$build/bin/bie_bench" --base "$1" --levels "$2" --backends direct,fmm --tol 1e-3,1e-4,1e-5,1e-6,1e-7,1e-8 \
      --direct-per-tol --repeat 5 --threads 2 --uniform-only | tee -a "$out"
done
python3 "$here/crossover.py" "$out"
