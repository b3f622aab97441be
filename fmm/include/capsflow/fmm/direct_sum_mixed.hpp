#pragma once
// capsflow::fmm::direct_sum_mixed<Kernel> — a kernel's direct sum (conventions of direct_sum.hpp;
// output OVERWRITTEN) with every pair in single precision and the sums in double;
// stokeslet_direct_sum_mixed is the Stokeslet's (the single layer's far field).
//
// With AVX-512 a float vector holds 16 pairs against 8 for double. The
// precision is kept where it matters:
//   - coordinates are shifted, in double, to the current target block's first target and split
//     into two floats, hi + lo; r = (t_hi − s_hi) + (t_lo − s_lo), whose first difference is exact
//     for nearby points (Sterbenz), so r keeps float ε relative accuracy even for |r| ≪ the
//     block's extent (close approach of two surfaces);
//   - 1/|r| from the 14-bit hardware estimate plus one Newton step (~2⁻²⁷ relative);
//   - float partial sums over at most kChunk sources are added to double accumulators.
// Measured on capsule meshes (Stokeslet): 1.3x the double kernel, max error 4e-7 of max |u|, 1e-7
// in L2 (tests/fmm/test_kernels.cpp checks close-approach clouds too, and the stresslet). Sources
// must not coincide with targets (no r = 0 test). Without AVX-512: direct_sum (one Newton step).
#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <vector>

#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/stokeslet.hpp"

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace capsflow::fmm {

/// True when direct_sum_mixed really sums single-precision pairs (AVX-512 builds).
#if defined(__AVX512F__)
inline constexpr bool kMixedPrecisionDirectSum = true;
#else
inline constexpr bool kMixedPrecisionDirectSum = false;
#endif

template <class Kernel>
void direct_sum_mixed(const double* src, std::size_t n_src, const double* density, const double* trg, std::size_t n_trg,
                      double* out, int threads = 0) {
#if !defined(__AVX512F__)
  direct_sum<Kernel, 1, false>(src, n_src, density, trg, n_trg, out, threads);
#else
  constexpr int SD = Kernel::src_dim, TD = Kernel::trg_dim;
  std::fill(out, out + TD * n_trg, 0.0);
  if (n_src == 0 || n_trg == 0) return;
  constexpr int kVec = 2;  // float vectors of targets per block (1: 1.1x, 2: 1.34x, 3-4: 1.35x over double)
  constexpr std::size_t kBlock = 16 * kVec;
  constexpr std::size_t kChunk = 512;  // sources summed in float before the double accumulation
  // Sources: coordinates in double (shifted per block), densities in float; structure of arrays,
  // padded to a multiple of 8 for the vectorised shift.
  const std::size_t ns8 = (n_src + 7) / 8 * 8;
  // Scratch reused across calls (per thread): no allocation once the sizes are reached.
  static thread_local std::vector<double> sx, sy, sz;
  static thread_local std::vector<float> fd;
  sx.assign(ns8, 0.0), sy.assign(ns8, 0.0), sz.assign(ns8, 0.0);
  fd.resize(SD * n_src);
  for (std::size_t j = 0; j < n_src; ++j) {
    sx[j] = src[3 * j], sy[j] = src[3 * j + 1], sz[j] = src[3 * j + 2];
    for (int k = 0; k < SD; ++k) fd[k * n_src + j] = static_cast<float>(density[SD * j + k]);
  }
  const long nblocks = static_cast<long>((n_trg + kBlock - 1) / kBlock);
  const int nt = threads > 0 ? threads : omp_get_max_threads();
  const double *src_x = sx.data(), *src_y = sy.data(), *src_z = sz.data();  // the caller's thread_local
  const float* den = fd.data();
#pragma omp parallel num_threads(nt)
  {
    static thread_local std::vector<float> ph[3], pl[3];  // sources relative to the block origin: hi, lo
    for (int d = 0; d < 3; ++d) ph[d].resize(ns8), pl[d].resize(ns8);
    const double* sc[3] = {src_x, src_y, src_z};
#pragma omp for schedule(dynamic, 1)
    for (long b = 0; b < nblocks; ++b) {
      const std::size_t i0 = static_cast<std::size_t>(b) * kBlock, ni = std::min(kBlock, n_trg - i0);
      const double c[3] = {trg[3 * i0], trg[3 * i0 + 1], trg[3 * i0 + 2]};
      for (int d = 0; d < 3; ++d) {
        const __m512d vc = _mm512_set1_pd(c[d]);
        for (std::size_t j = 0; j < ns8; j += 8) {
          const __m512d x = _mm512_sub_pd(_mm512_loadu_pd(sc[d] + j), vc);
          const __m256 hi = _mm512_cvtpd_ps(x);
          _mm256_storeu_ps(&ph[d][j], hi);
          _mm256_storeu_ps(&pl[d][j], _mm512_cvtpd_ps(_mm512_sub_pd(x, _mm512_cvtps_pd(hi))));
        }
      }
      // Targets relative to the same origin; lanes past the end repeat the origin (discarded).
      alignas(64) float th[3][kBlock], tl[3][kBlock];
      for (std::size_t k = 0; k < kBlock; ++k) {
        const std::size_t i = i0 + (k < ni ? k : 0);
        for (int d = 0; d < 3; ++d) {
          const double x = trg[3 * i + d] - c[d];
          th[d][k] = static_cast<float>(x);
          tl[d][k] = static_cast<float>(x - static_cast<double>(th[d][k]));
        }
      }
      __m512 TH[kVec][3], TL[kVec][3];
      for (int v = 0; v < kVec; ++v)
        for (int d = 0; d < 3; ++d) TH[v][d] = _mm512_load_ps(th[d] + 16 * v), TL[v][d] = _mm512_load_ps(tl[d] + 16 * v);
      __m512d acc[2 * TD * kVec];  // (vectors × TD components) × (low, high 8 lanes)
      for (auto& a : acc) a = _mm512_setzero_pd();
      for (std::size_t j0 = 0; j0 < n_src; j0 += kChunk) {
        const std::size_t j1 = std::min(n_src, j0 + kChunk);
        simd::VecF u[kVec][TD];
        for (auto& uv : u)
          for (auto& c : uv) c = _mm512_setzero_ps();
        for (std::size_t j = j0; j < j1; ++j) {
          const simd::VecF shx(ph[0][j]), shy(ph[1][j]), shz(ph[2][j]);
          const simd::VecF slx(pl[0][j]), sly(pl[1][j]), slz(pl[2][j]);
          simd::VecF g[SD];
          for (int k = 0; k < SD; ++k) g[k] = simd::VecF(den[k * n_src + j]);
          for (int v = 0; v < kVec; ++v) {
            const simd::VecF r[3] = {(simd::VecF(TH[v][0]) - shx) + (simd::VecF(TL[v][0]) - slx),
                                     (simd::VecF(TH[v][1]) - shy) + (simd::VecF(TL[v][1]) - sly),
                                     (simd::VecF(TH[v][2]) - shz) + (simd::VecF(TL[v][2]) - slz)};
            const simd::VecF r2 = simd::fma(r[0], r[0], simd::fma(r[1], r[1], r[2] * r[2]));
            Kernel::eval(u[v], r, simd::rsqrt(r2), g);
          }
        }
        for (int k = 0; k < TD * kVec; ++k) {
          const __m512 uk = u[k / TD][k % TD].v;
          acc[2 * k] = _mm512_add_pd(acc[2 * k], _mm512_cvtps_pd(_mm512_castps512_ps256(uk)));
          acc[2 * k + 1] =
              _mm512_add_pd(acc[2 * k + 1], _mm512_cvtps_pd(_mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(uk), 1))));
        }
      }
      alignas(64) double buf[TD * kVec][16];
      for (int k = 0; k < TD * kVec; ++k) {
        _mm512_store_pd(buf[k], acc[2 * k]);
        _mm512_store_pd(buf[k] + 8, acc[2 * k + 1]);
      }
      for (std::size_t k = 0; k < ni; ++k) {
        const int v = static_cast<int>(k / 16);
        const std::size_t lane = k % 16;
        for (int c = 0; c < TD; ++c) out[TD * (i0 + k) + c] = Kernel::scale() * buf[TD * v + c][lane];
      }
    }
  }
#endif
}

inline void stokeslet_direct_sum_mixed(const double* src, std::size_t n_src, const double* density, const double* trg,
                                       std::size_t n_trg, double* out, int threads = 0) {
  direct_sum_mixed<Stokeslet>(src, n_src, density, trg, n_trg, out, threads);
}

}  // namespace capsflow::fmm
