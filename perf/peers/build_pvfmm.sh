#!/usr/bin/env bash
# build_pvfmm.sh SNAPSHOT_DIR BUILD_DIR
#
# Benchmark-only build of PVFMM (https://github.com/dmalhotra/pvfmm) and of the driver
# pvfmm_stokes_bench.cpp beside this script. capsflow never links PVFMM; no PVFMM source is kept
# in this repository. SNAPSHOT_DIR is a plain PVFMM source tree whose SCTL/ folder holds the SCTL
# submodule (at the commit PVFMM's tree records); BUILD_DIR receives the CMake build
# (BUILD_DIR/pvfmm, static libpvfmm.a) and the driver BUILD_DIR/pvfmm_stokes_bench.
#
# Installs only Debian 12 packages (apt-get). Builds with nice -n 19 and -j${JOBS:-2} (at most 2).
set -euo pipefail
if [ $# -ne 2 ]; then echo "usage: $0 SNAPSHOT_DIR BUILD_DIR" >&2; exit 2; fi
SRC=$(cd "$1" && pwd)
mkdir -p "$2"; BUILD=$(cd "$2" && pwd)
HERE=$(cd "$(dirname "$0")" && pwd)
JOBS=${JOBS:-2}; [ "$JOBS" -gt 2 ] && JOBS=2
FLAGS="-O3 -march=native"

if [ ! -f "$SRC/CMakeLists.txt" ] || [ ! -f "$SRC/include/pvfmm.hpp" ]; then
  echo "build_pvfmm.sh: $SRC is not a PVFMM source tree" >&2; exit 2; fi
if [ ! -d "$SRC/SCTL/include/sctl" ]; then
  echo "build_pvfmm.sh: $SRC/SCTL is empty: extract the SCTL submodule there (see README.md)" >&2; exit 2; fi

# Debian 12 packages only.
PKGS="cmake g++ make libopenmpi-dev openmpi-bin libfftw3-dev libblas-dev liblapack-dev"
missing=""
for p in $PKGS; do dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"; done
if [ -n "$missing" ]; then
  echo "build_pvfmm.sh: apt-get install -y$missing"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $missing
fi

# PVFMM library (static; the examples are not built). PVFMM's CMakeLists.txt pins C++14
# (-std=c++14 comes last on the command line), but the SCTL it records uses C++17
# (std::aligned_alloc, if constexpr): with C++14 GCC 12 stops at sctl/scratch_pool.txx:38
# "'aligned_alloc' is not a member of 'std'". A compiler launcher in BUILD_DIR turns -std=c++14
# into -std=c++17; the sources are not touched.
cat > "$BUILD/cxx17-launcher.sh" <<'EOS'
#!/bin/sh
# Compiler launcher for the PVFMM benchmark build: -std=c++14 -> -std=c++17.
cmd=$1; shift
for a in "$@"; do
  shift
  if [ "$a" = "-std=c++14" ]; then set -- "$@" -std=c++17; else set -- "$@" "$a"; fi
done
exec "$cmd" "$@"
EOS
chmod +x "$BUILD/cxx17-launcher.sh"
cmake -S "$SRC" -B "$BUILD/pvfmm" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_COMPILER_LAUNCHER="$BUILD/cxx17-launcher.sh" \
  -DCMAKE_C_COMPILER=gcc -DCMAKE_CXX_COMPILER=g++ \
  -DCMAKE_CXX_FLAGS="$FLAGS" -DCMAKE_C_FLAGS="$FLAGS" \
  -DCMAKE_CXX_FLAGS_RELEASE="" -DCMAKE_C_FLAGS_RELEASE=""
nice -n 19 cmake --build "$BUILD/pvfmm" --target pvfmmStatic -j"$JOBS"

# The driver: compiled with the same definitions PVFMM's CMake gives its own targets.
MPI_CFLAGS=$(mpicxx --showme:compile)
MPI_LIBS=$(mpicxx --showme:link)
nice -n 19 g++ -std=c++17 $FLAGS -fopenmp \
  -DHAVE_CONFIG_H -DSCTL_QUAD_T=__float128 -DSCTL_HAVE_BLAS -DSCTL_HAVE_LAPACK -DSCTL_HAVE_FFTW \
  -I"$BUILD/pvfmm" -I"$SRC/include" -I"$SRC/SCTL/include" $MPI_CFLAGS \
  "$HERE/pvfmm_stokes_bench.cpp" -o "$BUILD/pvfmm_stokes_bench" \
  "$BUILD/pvfmm/libpvfmm.a" -lfftw3_omp -lfftw3 -lfftw3f_omp -lfftw3f -llapack -lblas $MPI_LIBS -lm
echo "built $BUILD/pvfmm_stokes_bench"
