#!/usr/bin/env bash
# Bisection of the largest stable fixed time step: the calibration of dt = "auto"
# (src/include/capsflow/core/stepping/stability.hpp, perf/RESULTS.md §3.1, docs/time-integration.md §5.9.3).
#
# A run "blows up" when capsflow stops with exit code 3 (stop_reason blow_up) before t_end; the
# script bisects dt between a stable and an unstable value and prints one JSON line:
#   {"level":..,"law":..,"ca_s":..,"stable":dt_lo,"unstable":dt_hi,"min_edge":..,"c_m":..}
# with c_m = dt_lo (1 + K_s/G_s) / (Ca_s Δx) the membrane constant this case supports.
#
# Usage: perf/stability/bisect_dt.sh LEVEL LAW CA_S [MODEL] [extra --set ...]
#   e.g. perf/stability/bisect_dt.sh 2 gh 0.1            # membrane wall, a/b = 1.4 spheroid
#        perf/stability/bisect_dt.sh 3 gh 0.1 gsmb --set wall.thickness=0.3
# Environment: CAPSFLOW (default build/bin/capsflow), T_END (1.5), ITER (8), THREADS (2).
set -euo pipefail
level=$1 law=$2 ca=$3 model=${4:-membrane}
shift $(( $# >= 4 ? 4 : 3 ))
exe=${CAPSFLOW:-build/bin/capsflow}
t_end=${T_END:-1.5} iters=${ITER:-8} threads=${THREADS:-2}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
common=(--set "mesh.level=$level" --set "wall.law=\"$law\"" --set "wall.model=\"$model\"" --set "flow.ca_s=$ca"
        --set "time.t_end=$t_end" --set output.every=0.5 --set output.checkpoint_every=0 "$@")

# Reference numbers from `capsflow info`: the auto step (safety 1) and the mesh's shortest edge.
info=$("$exe" info "${common[@]}")
auto_dt=$(grep -oP '^stable dt\s+\K[0-9.e+-]+' <<<"$info")
min_edge=$(grep -oP '^edge length\s+min \K[0-9.e+-]+' <<<"$info")

blows_up() {  # $1 = dt; true when the run stops with blow_up
  local rc=0
  "$exe" run "${common[@]}" --set "time.dt=$1" --threads "$threads" -o "$work/run" --overwrite >/dev/null 2>&1 || rc=$?
  [[ $rc -eq 3 ]] && return 0
  [[ $rc -eq 0 ]] && return 1
  echo "bisect_dt: capsflow exited $rc at dt = $1" >&2
  exit 1
}

lo=$(python3 -c "print($auto_dt / 4)") hi=$(python3 -c "print($auto_dt * 4)")
blows_up "$lo" && { echo "bisect_dt: dt = $lo already unstable" >&2; exit 1; }
blows_up "$hi" || { echo "bisect_dt: dt = $hi still stable" >&2; exit 1; }
for ((i = 0; i < iters; ++i)); do
  mid=$(python3 -c "import math; print(math.sqrt($lo * $hi))")
  if blows_up "$mid"; then hi=$mid; else lo=$mid; fi
done
python3 - "$level" "$law" "$ca" "$lo" "$hi" "$min_edge" "$model" <<'PY'
import json, sys
level, law, ca, lo, hi, dx, model = sys.argv[1:]
ca, lo, hi, dx = map(float, (ca, lo, hi, dx))
# K_s/G_s: 3 for GH with the default nu = 0.5, NH, and Skalak with the default C = 1.
ratio = {"gh": 3.0, "nh": 3.0, "skalak": 3.0}[law]
print(json.dumps({"level": int(level), "law": law, "model": model, "ca_s": ca, "stable": lo, "unstable": hi,
                  "min_edge": dx, "c_m": lo * (1 + ratio) / (ca * dx)}))
PY
