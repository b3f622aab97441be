#!/usr/bin/env bash
# Peak resident memory of short runs (γ̇t = 0.001) of the built-in scene by mesh level, viscosity
# ratio and back end: summary.json's peak_rss_mb (getrusage), 2 threads. The data behind
# src/info/memory_estimate.cpp (perf/RESULTS.md §1.9). Run alone on the machine; level 8 needs ~7 GB
# and λ = 5 at level 7 ~6.5 GB.
#
#   perf/memory/peak_memory.sh build/bin/capsflow OUTDIR [CASE...]
#   CASE: LEVEL:LAMBDA:BACKEND[:TOLERANCE] (fluid.tolerance, default "auto"), default the table's
#   short runs at the default tolerance
set -euo pipefail
exe=$1 out=$2
shift 2
cases=("$@")
if ((${#cases[@]} == 0)); then
  cases=(3:1:direct 4:1:direct 5:1:direct 4:1:fmm 5:1:fmm 6:1:fmm 7:1:fmm 8:1:fmm
         4:1:fmm:1e-6 5:1:fmm:1e-6 6:1:fmm:1e-6 7:1:fmm:1e-6 8:1:fmm:1e-6
         3:5:direct 4:5:direct 5:5:direct 5:5:fmm 6:5:fmm 7:5:fmm)
fi
mkdir -p "$out"
printf '%-6s %-7s %-7s %-9s %10s %9s\n' level lambda backend tolerance peak_mb seconds
for c in "${cases[@]}"; do
  IFS=: read -r level lambda backend tolerance <<<"$c"
  tolerance=${tolerance:-'"auto"'}
  dir="$out/L${level}_lambda${lambda}_${backend}_${tolerance//\"/}"
  start=$(date +%s.%N)
  "$exe" run --set mesh.level="$level" --set fluid.viscosity_ratio="$lambda" --set fluid.backend="$backend" --set fluid.tolerance="$tolerance" \
    --set time.t_end=0.001 --threads 2 -o "$dir" --overwrite >"$dir.log" 2>&1
  end=$(date +%s.%N)
  peak=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['peak_rss_mb'])" "$dir/summary.json")
  printf '%-6s %-7s %-7s %-9s %10.1f %9.1f\n' "$level" "$lambda" "$backend" "${tolerance//\"/}" "$peak" "$(python3 -c "print($end - $start)")"
done
