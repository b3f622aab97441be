#pragma once
// Deterministic OpenMP helpers: reductions are summed over fixed-size chunks (independent of the
// thread count), then the chunk partials are added serially, so results are bit-identical for any
// number of threads.
#include <algorithm>
#include <vector>

#include "capsflow/shell/parallel_thresholds.hpp"

namespace capsflow::shell::par {

/// Terms per chunk: fixes the summation order (changing it changes the last bits of results).
inline constexpr long kChunk = 4096;

/// sum_i f(i) for i in [0, n), deterministic. `partial` is scratch (resized if needed).
template <class F>
double det_sum(long n, std::vector<double>& partial, F&& f) {
  const long nc = (n + kChunk - 1) / kChunk;
  if (static_cast<long>(partial.size()) < nc) partial.resize(nc);
#pragma omp parallel for schedule(static) if (n > kParallelSumTerms)
  for (long c = 0; c < nc; ++c) {
    double s = 0;
    const long e = std::min(n, (c + 1) * kChunk);
    for (long i = c * kChunk; i < e; ++i) s += f(i);
    partial[c] = s;
  }
  double s = 0;
  for (long c = 0; c < nc; ++c) s += partial[c];
  return s;
}

inline double dot(long n, const double* a, const double* b, std::vector<double>& partial) {
  return det_sum(n, partial, [&](long i) { return a[i] * b[i]; });
}

}  // namespace capsflow::shell::par
