// direct_bench — pairs per second of capsflow::fmm::direct_sum (the SIMD/OpenMP direct sum).
//   direct_bench [--n 20000] [--ntrg 20000] [--threads T] [--reps 3] [--kernel stokeslet|stresslet]
// Prints one JSON line: kernel, n, ntrg, threads, seconds (median), pairs_per_s, isa.
#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/stokeslet.hpp"
#include "capsflow/fmm/stresslet.hpp"
#include "points.hpp"

namespace {
template <class Kernel>
void run(std::size_t n, std::size_t nt, int threads, int reps) {
  auto s = capsflow::fmm::testing::make_points("sphere", n, 1);
  auto t = capsflow::fmm::testing::make_points("sphere", nt, 2);
  auto f = capsflow::fmm::testing::random_density(Kernel::src_dim * n, 3);
  std::vector<double> u(Kernel::trg_dim * nt), ts;
  for (int r = 0; r < reps; ++r) {
    const double t0 = omp_get_wtime();
    capsflow::fmm::direct_sum<Kernel>(s.data(), n, f.data(), t.data(), nt, u.data(), threads);
    ts.push_back(omp_get_wtime() - t0);
  }
  std::sort(ts.begin(), ts.end());
  const double med = ts[ts.size() / 2];
  std::printf("{\"what\":\"direct\",\"kernel\":\"%s\",\"n\":%zu,\"ntrg\":%zu,\"threads\":%d,\"seconds\":%.4f,"
              "\"pairs_per_s\":%.3e,\"isa\":\"%s\"}\n",
              Kernel::name, n, nt, threads > 0 ? threads : omp_get_max_threads(), med, double(n) * double(nt) / med,
              capsflow::fmm::simd::isa_name());
}
}  // namespace

int main(int argc, char** argv) {
  std::size_t n = 20000, nt = 20000;
  int threads = 0, reps = 3;
  std::string kernel = "stokeslet";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--n") n = static_cast<std::size_t>(std::stod(argv[i + 1]));
    else if (k == "--ntrg") nt = static_cast<std::size_t>(std::stod(argv[i + 1]));
    else if (k == "--threads") threads = std::stoi(argv[i + 1]);
    else if (k == "--reps") reps = std::stoi(argv[i + 1]);
    else if (k == "--kernel") kernel = argv[i + 1];
  }
  if (kernel == "stresslet") run<capsflow::fmm::Stresslet>(n, nt, threads, reps);
  else if (kernel == "stokeslet") run<capsflow::fmm::Stokeslet>(n, nt, threads, reps);
  else {
    std::fprintf(stderr, "direct_bench: unknown kernel %s\n", kernel.c_str());
    return 2;
  }
}
