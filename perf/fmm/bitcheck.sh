#!/bin/sh
# Are the Stokeslet FMM's outputs bit for bit the same at two git revisions? For changes to fmm/
# that must not alter the Stokeslet (e.g. the equivalent kernels of docs/fmm.md §3.10).
#   perf/fmm/bitcheck.sh REV_A REV_B [N]        (from the repository; N points, default 20000)
# Builds one small program against each revision's fmm/ and tests/fmm/points.hpp (git archive,
# the compiler flags of a CAPSFLOW_NATIVE Release build), runs it with a cold operator cache and
# again with the warm one, and compares the raw output doubles with cmp. Cases: sphere
# (sources = targets) and clustered (N/3 separate targets), orders 6, 8 and 10, 1 and 3
# densities per call, 2 threads. Not a timing: run it on a loaded machine if need be (~5 minutes).
set -eu
A=${1:?revision A}
B=${2:?revision B}
N=${3:-20000}
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cat > "$W/dump.cpp" <<'EOF'
// writes the Stokeslet FMM's outputs of fixed cases as raw doubles to argv[1]
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "capsflow/fmm/fmm.hpp"
#include "capsflow/fmm/stokeslet.hpp"
#include "points.hpp"

using namespace capsflow::fmm;

int main(int argc, char** argv) {
  std::FILE* out = std::fopen(argv[1], "wb");
  const std::size_t n = std::strtoul(argv[2], nullptr, 10);
  for (const std::string dist : {"sphere", "clustered"}) {
    const bool same = dist == "sphere";
    const auto s = testing::make_points(dist, n, 1);
    const auto t = same ? s : testing::make_points(dist, n / 3, 2);
    const std::size_t nt = t.size() / 3;
    for (int p : {6, 8, 10})
      for (int k : {1, 3}) {
        FmmOptions o;
        o.order = p;
        o.threads = 2;
        o.cache_dir = argv[3];
        Fmm<Stokeslet> fmm(o);
        fmm.setup(s.data(), n, t.data(), nt);
        const auto f = testing::random_density(3 * n * k, 7);
        std::vector<double> u(3 * nt * k);
        fmm.evaluate(f.data(), u.data(), k);
        std::fwrite(u.data(), sizeof(double), u.size(), out);
      }
  }
  return std::fclose(out) == 0 ? 0 : 1;
}
EOF
for R in "$A" "$B"; do
  D="$W/$(echo "$R" | tr -c 'A-Za-z0-9_\n' _)"
  mkdir -p "$D/src" "$D/cache"
  git archive "$R" fmm tests/fmm/points.hpp | tar -x -C "$D/src"
  c++ -O3 -DNDEBUG -fopenmp -march=native -std=c++17 -w -I"$D/src/fmm/include" -I"$D/src/tests/fmm" \
    -isystem /usr/include/eigen3 "$W/dump.cpp" "$D"/src/fmm/src/*.cpp -o "$D/dump" \
    $(pkg-config --libs fftw3) -lfftw3_omp
  "$D/dump" "$D/cold.bin" "$N" "$D/cache"
  "$D/dump" "$D/warm.bin" "$N" "$D/cache"
done
DA="$W/$(echo "$A" | tr -c 'A-Za-z0-9_\n' _)"
DB="$W/$(echo "$B" | tr -c 'A-Za-z0-9_\n' _)"
echo "$(wc -c < "$DA/cold.bin") bytes of output per run"
cmp "$DA/cold.bin" "$DA/warm.bin" && cmp "$DA/cold.bin" "$DB/cold.bin" && cmp "$DB/cold.bin" "$DB/warm.bin" &&
  echo "bit-identical: $A and $B, cold and warm operator cache"
