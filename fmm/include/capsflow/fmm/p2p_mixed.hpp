#pragma once
// capsflow::fmm::p2p_mixed — the pair kernel with every pair in single precision and the sums in
// double: u[k][i] += scale · Σ_j K_k(t_i − s_j) f_j (ACCUMULATES, like p2p), structure of arrays.
//
// Where the accuracy is kept:
//   - coordinates are shifted, in double, to the first target and split into two floats, hi + lo;
//     r = (t_hi − s_hi) + (t_lo − s_lo), whose first difference is exact for nearby points
//     (Sterbenz), so r keeps float ε relative accuracy even for |r| much smaller than the points'
//     extent (the close approach of two surfaces);
//   - 1/|r| from the hardware estimate plus one Newton step (simd::rsqrt on VecF);
//   - float partial sums over at most kChunk sources are added to double accumulators.
// Each pair carries float rounding (r, f, 1/|r|, the partial sums): random sums come to ~4e-7 in
// L2 (tests/fmm/test_kernels.cpp), the same with an exact float 1/sqrt as with the estimate. Masked = true skips
// coincident pairs (r = 0), false requires that no target coincides with a source.
// Without a single-precision vector type (simd::kHasSinglePrecisionPairs false) it is p2p with one
// Newton step.
#include <algorithm>
#include <cstddef>
#include <vector>

#include "capsflow/fmm/p2p.hpp"
#include "capsflow/fmm/simd.hpp"

namespace capsflow::fmm {

#if defined(__AVX512F__) || (defined(__AVX2__) && defined(__FMA__))
template <class Kernel, bool Masked = true>
inline void p2p_mixed(const double* tx, const double* ty, const double* tz, std::size_t nt,
                      const double* sx, const double* sy, const double* sz,
                      const double* const* f, std::size_t ns, double* const* u, double scale) {
  using V = simd::VecF;
  constexpr int W = V::width, SD = Kernel::src_dim, TD = Kernel::trg_dim;
  constexpr int kVec = 2;               // float vectors of targets per block (ILP)
  constexpr std::size_t kBlock = W * kVec;
  constexpr std::size_t kChunk = 512;   // sources summed in float before the double accumulation
  if (nt == 0 || ns == 0) return;
  const double c[3] = {tx[0], ty[0], tz[0]};
  const double* const s[3] = {sx, sy, sz};
  // Scratch per thread, reused across calls: sources relative to c (hi, lo) and float densities.
  static thread_local std::vector<float> sh[3], sl[3], fd[SD];
  for (int d = 0; d < 3; ++d) {
    if (sh[d].size() < ns) sh[d].resize(ns), sl[d].resize(ns);
    float* hi = sh[d].data();
    float* lo = sl[d].data();
    for (std::size_t j = 0; j < ns; ++j) {
      const double x = s[d][j] - c[d];
      hi[j] = static_cast<float>(x);
      lo[j] = static_cast<float>(x - static_cast<double>(hi[j]));
    }
  }
  for (int k = 0; k < SD; ++k) {
    if (fd[k].size() < ns) fd[k].resize(ns);
    for (std::size_t j = 0; j < ns; ++j) fd[k][j] = static_cast<float>(f[k][j]);
  }
  const double* const t[3] = {tx, ty, tz};
  for (std::size_t i0 = 0; i0 < nt; i0 += kBlock) {
    const std::size_t ni = std::min(kBlock, nt - i0);
    // targets relative to c; lanes past the end repeat the block's first target (discarded)
    alignas(64) float th[3][kBlock], tl[3][kBlock];
    for (std::size_t k = 0; k < kBlock; ++k) {
      const std::size_t i = i0 + (k < ni ? k : 0);
      for (int d = 0; d < 3; ++d) {
        const double x = t[d][i] - c[d];
        th[d][k] = static_cast<float>(x);
        tl[d][k] = static_cast<float>(x - static_cast<double>(th[d][k]));
      }
    }
    V TH[kVec][3], TL[kVec][3];
    for (int v = 0; v < kVec; ++v)
      for (int d = 0; d < 3; ++d) TH[v][d] = V::load(th[d] + W * v), TL[v][d] = V::load(tl[d] + W * v);
    alignas(64) double acc[kVec * TD][W] = {};
    for (std::size_t j0 = 0; j0 < ns; j0 += kChunk) {
      const std::size_t j1 = std::min(ns, j0 + kChunk);
      V a[kVec][TD];
      for (auto& av : a)
        for (auto& x : av) x = V(0.0f);
      for (std::size_t j = j0; j < j1; ++j) {
        const V shx(sh[0][j]), shy(sh[1][j]), shz(sh[2][j]), slx(sl[0][j]), sly(sl[1][j]), slz(sl[2][j]);
        V g[SD];
        for (int k = 0; k < SD; ++k) g[k] = V(fd[k][j]);
        for (int v = 0; v < kVec; ++v) {
          const V r[3] = {(TH[v][0] - shx) + (TL[v][0] - slx), (TH[v][1] - shy) + (TL[v][1] - sly),
                          (TH[v][2] - shz) + (TL[v][2] - slz)};
          const V r2 = simd::fma(r[0], r[0], simd::fma(r[1], r[1], r[2] * r[2]));
          V ri = simd::rsqrt(r2);
          if constexpr (Masked) ri = simd::zero_where_coincident(ri, r2);
          Kernel::eval(a[v], r, ri, g);
        }
      }
      for (int v = 0; v < kVec; ++v)
        for (int k = 0; k < TD; ++k) {
          alignas(64) float b[W];
          a[v][k].store(b);
          for (int l = 0; l < W; ++l) acc[v * TD + k][l] += b[l];
        }
    }
    for (std::size_t k = 0; k < ni; ++k)
      for (int q = 0; q < TD; ++q) u[q][i0 + k] += scale * acc[(k / W) * TD + q][k % W];
  }
}
#else
template <class Kernel, bool Masked = true>
inline void p2p_mixed(const double* tx, const double* ty, const double* tz, std::size_t nt,
                      const double* sx, const double* sy, const double* sz,
                      const double* const* f, std::size_t ns, double* const* u, double scale) {
  p2p<Kernel, 1, Masked>(tx, ty, tz, nt, sx, sy, sz, f, ns, u, scale);
}
#endif

}  // namespace capsflow::fmm
