#pragma once
// capsflow::fmm::direct_sum — O(N·M) summation, public: the oracle for tests and the small-N back end.
//
//   out[i*trg_dim + a] = Kernel::scale() Σ_j K_ab(trg_i − src_j) density[j*src_dim + b]
// Points are xyz-interleaved (x0,y0,z0,x1,...), densities src_dim per source, outputs trg_dim per
// target, in the caller's order. The output is OVERWRITTEN. Pairs at distance 0 are skipped.
// OpenMP over target blocks (owner computes), SIMD inside (simd::VecD), sources tiled for cache.
#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <vector>

#include "capsflow/fmm/p2p.hpp"

namespace capsflow::fmm {

namespace detail {
/// The direct sum's frame, shared by direct_sum and direct_sum_mixed: the points and densities
/// copied to structure-of-arrays scratch (per calling thread, reused: no allocation once the sizes
/// are reached; the parallel region sees it only through pointers), OpenMP over target blocks of
/// 128, sources in tiles of 4 096 for cache, and `pairs` (p2p's signature: it accumulates) on each
/// block and tile. The output is OVERWRITTEN, in the caller's order.
template <class Kernel, class Pairs>
void direct_sum_by_blocks(const double* src, std::size_t n_src, const double* density, const double* trg,
                          std::size_t n_trg, double* out, int threads, Pairs pairs) {
  constexpr int SD = Kernel::src_dim, TD = Kernel::trg_dim;
  std::fill(out, out + n_trg * TD, 0.0);
  if (n_src == 0 || n_trg == 0) return;
  static thread_local std::vector<double> s_buf, t_buf;
  s_buf.resize(n_src * (3 + SD));
  t_buf.assign(n_trg * (3 + TD), 0.0);
  double* const s = s_buf.data();
  double* const t = t_buf.data();
  for (std::size_t j = 0; j < n_src; ++j) {
    for (int d = 0; d < 3; ++d) s[d * n_src + j] = src[3 * j + d];
    for (int k = 0; k < SD; ++k) s[(3 + k) * n_src + j] = density[SD * j + k];
  }
  for (std::size_t i = 0; i < n_trg; ++i)
    for (int d = 0; d < 3; ++d) t[d * n_trg + i] = trg[3 * i + d];
  const double* f[SD];
  for (int k = 0; k < SD; ++k) f[k] = s + (3 + k) * n_src;
  double* u[TD];
  for (int k = 0; k < TD; ++k) u[k] = t + (3 + k) * n_trg;
  constexpr std::size_t tblock = 128, sblock = 4096;
  const long nblocks = static_cast<long>((n_trg + tblock - 1) / tblock);
  const int nt = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt)
  for (long b = 0; b < nblocks; ++b) {
    const std::size_t i0 = static_cast<std::size_t>(b) * tblock;
    const std::size_t ni = std::min(tblock, n_trg - i0);
    double* ub[TD];
    for (int k = 0; k < TD; ++k) ub[k] = u[k] + i0;
    for (std::size_t j0 = 0; j0 < n_src; j0 += sblock) {
      const std::size_t nj = std::min(sblock, n_src - j0);
      const double* fb[SD];
      for (int k = 0; k < SD; ++k) fb[k] = f[k] + j0;
      pairs(t + i0, t + n_trg + i0, t + 2 * n_trg + i0, ni, s + j0, s + n_src + j0, s + 2 * n_src + j0, fb, nj, ub,
            Kernel::scale());
    }
  }
  for (std::size_t i = 0; i < n_trg; ++i)
    for (int k = 0; k < TD; ++k) out[TD * i + k] = u[k][i];
}
}  // namespace detail

// Newton / Masked as in p2p.hpp: the defaults give full double accuracy and skip coincident pairs;
// callers that know sources and targets are disjoint and need < 1e-8 may relax them.
template <class Kernel, int Newton = 2, bool Masked = true>
void direct_sum(const double* src, std::size_t n_src, const double* density, const double* trg,
                std::size_t n_trg, double* out, int threads = 0) {
  detail::direct_sum_by_blocks<Kernel>(src, n_src, density, trg, n_trg, out, threads,
                                       [](auto... a) { p2p<Kernel, Newton, Masked>(a...); });
}

}  // namespace capsflow::fmm
