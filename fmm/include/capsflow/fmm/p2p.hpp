#pragma once
// capsflow::fmm::p2p — the SIMD particle-to-particle micro-kernel, generated from a kernel struct.
//
// Structure-of-arrays inputs. Vectorised over targets (simd::VecD lanes), each source broadcast;
// two target vectors per source for instruction-level parallelism. Self pairs (r = 0) add 0.
// u[k][i] += scale * Σ_j K_k(t_i − s_j) f_j    (ACCUMULATES into u).
// Newton = number of Newton steps after the hardware rsqrt estimate (AVX-512 path only):
// 2 = full double accuracy (default, direct_sum); 1 = relative error < 6e-9 per pair.
// Masked = false: the caller guarantees no target coincides with a source (saves the test).
#include <cstddef>

#include "capsflow/fmm/simd.hpp"

namespace capsflow::fmm {

template <class Kernel, int Newton = 2, bool Masked = true>
inline void p2p(const double* tx, const double* ty, const double* tz, std::size_t nt,
                const double* sx, const double* sy, const double* sz,
                const double* const* f, std::size_t ns, double* const* u, double scale) {
  using V = simd::VecD;
  constexpr int W = V::width;
  constexpr int SD = Kernel::src_dim, TD = Kernel::trg_dim;
  const V vscale(scale);
  std::size_t i = 0;
  // two full vectors of targets at a time
  for (; i + 2 * W <= nt; i += 2 * W) {
    const V x0 = V::load(tx + i), y0 = V::load(ty + i), z0 = V::load(tz + i);
    const V x1 = V::load(tx + i + W), y1 = V::load(ty + i + W), z1 = V::load(tz + i + W);
    V a0[TD], a1[TD];
    for (int k = 0; k < TD; ++k) { a0[k] = V(0.0); a1[k] = V(0.0); }
    for (std::size_t j = 0; j < ns; ++j) {
      const V px(sx[j]), py(sy[j]), pz(sz[j]);
      V fv[SD];
      for (int k = 0; k < SD; ++k) fv[k] = V(f[k][j]);
      const V r0[3] = {x0 - px, y0 - py, z0 - pz};
      const V r1[3] = {x1 - px, y1 - py, z1 - pz};
      const V q0 = simd::fma(r0[0], r0[0], simd::fma(r0[1], r0[1], r0[2] * r0[2]));
      const V q1 = simd::fma(r1[0], r1[0], simd::fma(r1[1], r1[1], r1[2] * r1[2]));
      const V ri0 = simd::rsqrt<Newton, Masked>(q0), ri1 = simd::rsqrt<Newton, Masked>(q1);
      Kernel::eval(a0, r0, ri0, fv);
      Kernel::eval(a1, r1, ri1, fv);
    }
    for (int k = 0; k < TD; ++k) {
      (a0[k] * vscale).add_to(u[k] + i);
      (a1[k] * vscale).add_to(u[k] + i + W);
    }
  }
  // remaining targets, one (possibly partial) vector at a time
  for (; i < nt; i += W) {
    const int m = static_cast<int>(nt - i < static_cast<std::size_t>(W) ? nt - i : W);
    const V x0 = V::load_partial(tx + i, m), y0 = V::load_partial(ty + i, m),
            z0 = V::load_partial(tz + i, m);
    V a0[TD];
    for (int k = 0; k < TD; ++k) a0[k] = V(0.0);
    for (std::size_t j = 0; j < ns; ++j) {
      const V px(sx[j]), py(sy[j]), pz(sz[j]);
      V fv[SD];
      for (int k = 0; k < SD; ++k) fv[k] = V(f[k][j]);
      const V r0[3] = {x0 - px, y0 - py, z0 - pz};
      const V q0 = simd::fma(r0[0], r0[0], simd::fma(r0[1], r0[1], r0[2] * r0[2]));
      Kernel::eval(a0, r0, simd::rsqrt<Newton, Masked>(q0), fv);
    }
    for (int k = 0; k < TD; ++k) (a0[k] * vscale).add_to_partial(u[k] + i, m);
  }
}

/// Scalar reference (plain double, 1/std::sqrt): the oracle for the SIMD kernel test.
template <class Kernel>
inline void p2p_reference(const double* tx, const double* ty, const double* tz, std::size_t nt,
                          const double* sx, const double* sy, const double* sz,
                          const double* const* f, std::size_t ns, double* const* u, double scale) {
  constexpr int SD = Kernel::src_dim, TD = Kernel::trg_dim;
  for (std::size_t i = 0; i < nt; ++i) {
    double a[TD] = {};
    for (std::size_t j = 0; j < ns; ++j) {
      const double r[3] = {tx[i] - sx[j], ty[i] - sy[j], tz[i] - sz[j]};
      const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
      const double ri = r2 > 0 ? 1.0 / std::sqrt(r2) : 0.0;
      double fv[SD];
      for (int k = 0; k < SD; ++k) fv[k] = f[k][j];
      Kernel::eval(a, r, ri, fv);
    }
    for (int k = 0; k < TD; ++k) u[k][i] += scale * a[k];
  }
}

}  // namespace capsflow::fmm
