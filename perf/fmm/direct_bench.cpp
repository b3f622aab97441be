// direct_bench — pairs per second of capsflow::fmm::direct_sum (the SIMD/OpenMP direct sum).
//   direct_bench [--n 20000] [--ntrg 20000] [--threads T] [--reps 3] [--kernel stokeslet|stresslet]
//                [--pairs exact|fast|single]
// --pairs: exact (default: two Newton steps / exact 1/sqrt), fast (one Newton step, no r = 0 test:
// the boundary integral's double pairs), single (direct_sum_mixed: single-precision pairs).
// Prints one JSON line: kernel, pairs, n, ntrg, threads, seconds (median), pairs_per_s,
// rel_l2 (against the exact pairs), isa.
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/direct_sum_mixed.hpp"
#include "capsflow/fmm/stokeslet.hpp"
#include "capsflow/fmm/stresslet.hpp"
#include "points.hpp"

namespace {
template <class Kernel>
void run(std::size_t n, std::size_t nt, int threads, int reps, const std::string& pairs) {
  auto s = capsflow::fmm::testing::make_points("sphere", n, 1);
  auto t = capsflow::fmm::testing::make_points("sphere", nt, 2);
  auto f = capsflow::fmm::testing::random_density(Kernel::src_dim * n, 3);
  std::vector<double> u(Kernel::trg_dim * nt), ref(u.size()), ts;
  capsflow::fmm::direct_sum<Kernel>(s.data(), n, f.data(), t.data(), nt, ref.data(), threads);
  for (int r = 0; r < reps; ++r) {
    const double t0 = omp_get_wtime();
    if (pairs == "single") capsflow::fmm::direct_sum_mixed<Kernel>(s.data(), n, f.data(), t.data(), nt, u.data(), threads);
    else if (pairs == "fast") capsflow::fmm::direct_sum<Kernel, 1, false>(s.data(), n, f.data(), t.data(), nt, u.data(), threads);
    else capsflow::fmm::direct_sum<Kernel>(s.data(), n, f.data(), t.data(), nt, u.data(), threads);
    ts.push_back(omp_get_wtime() - t0);
  }
  double e2 = 0, r2 = 0;
  for (std::size_t i = 0; i < u.size(); ++i) e2 += (u[i] - ref[i]) * (u[i] - ref[i]), r2 += ref[i] * ref[i];
  std::sort(ts.begin(), ts.end());
  const double med = ts[ts.size() / 2];
  std::printf("{\"what\":\"direct\",\"kernel\":\"%s\",\"pairs\":\"%s\",\"n\":%zu,\"ntrg\":%zu,\"threads\":%d,"
              "\"seconds\":%.4f,\"pairs_per_s\":%.3e,\"rel_l2\":%.2e,\"isa\":\"%s\"}\n",
              Kernel::name, pairs.c_str(), n, nt, threads > 0 ? threads : omp_get_max_threads(), med,
              double(n) * double(nt) / med, r2 > 0 ? std::sqrt(e2 / r2) : 0.0, capsflow::fmm::simd::isa_name());
}
}  // namespace

int main(int argc, char** argv) {
  std::size_t n = 20000, nt = 20000;
  int threads = 0, reps = 3;
  std::string kernel = "stokeslet", pairs = "exact";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--n") n = static_cast<std::size_t>(std::stod(argv[i + 1]));
    else if (k == "--ntrg") nt = static_cast<std::size_t>(std::stod(argv[i + 1]));
    else if (k == "--threads") threads = std::stoi(argv[i + 1]);
    else if (k == "--reps") reps = std::stoi(argv[i + 1]);
    else if (k == "--kernel") kernel = argv[i + 1];
    else if (k == "--pairs") pairs = argv[i + 1];
  }
  if (pairs != "exact" && pairs != "fast" && pairs != "single") {
    std::fprintf(stderr, "direct_bench: --pairs must be exact, fast or single, not %s\n", pairs.c_str());
    return 2;
  }
  if (kernel == "stresslet") run<capsflow::fmm::Stresslet>(n, nt, threads, reps, pairs);
  else if (kernel == "stokeslet") run<capsflow::fmm::Stokeslet>(n, nt, threads, reps, pairs);
  else {
    std::fprintf(stderr, "direct_bench: unknown kernel %s\n", kernel.c_str());
    return 2;
  }
}
