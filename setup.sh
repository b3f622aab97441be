#!/usr/bin/env bash
# capsflow set-up on a fresh Debian 12 machine: installs what is missing (as root, or with sudo),
# configures and builds (Release, -march=native, ccache when present), then either runs the main
# job or the test suite. Idempotent: a second call with nothing changed only re-checks and runs.
#
#   ./setup.sh run [capsflow run options...]   # default scene, output in ./capsflow-out
#   ./setup.sh test                            # the default suite (labels unit and integration)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"

mode="${1:-}"
[[ "$mode" == run || "$mode" == test ]] || { echo "usage: ./setup.sh run|test [args...]" >&2; exit 2; }
shift

packages=(cmake ninja-build g++ pkg-config ccache git
          libeigen3-dev libfftw3-dev libhdf5-dev libtomlplusplus-dev libcli11-dev nlohmann-json3-dev
          libspdlog-dev libfmt-dev libgtest-dev python3-matplotlib python3-numpy python3-h5py
          python3-dev python3-pybind11 python3-pytest)
# The Slurm tests run a one-node cluster on localhost (tests/slurm/local_cluster.sh, docs/testing.md).
if [[ $mode == test ]]; then packages+=(slurm-wlm munge); fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo=""
  [[ $(id -u) -eq 0 ]] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

build=build
if [[ ! -f $build/build.ninja ]]; then
  cmake -S . -B $build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCAPSFLOW_NATIVE=ON
fi
cmake --build $build -j"$(nproc)"

if [[ $mode == run ]]; then
  if [[ $# -eq 0 ]]; then set -- -o capsflow-out --overwrite; fi
  exec "$build/bin/capsflow" run "$@"
else
  exec ctest --test-dir $build -L 'unit|integration' --output-on-failure -j2 --timeout 600 "$@"
fi
