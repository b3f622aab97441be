#pragma once
// capsflow::fmm::p2p — the SIMD particle-to-particle micro-kernel, generated from a kernel struct.
//
// Structure-of-arrays inputs. Vectorised over targets (simd::VecD lanes), each source broadcast;
// two target vectors per source for instruction-level parallelism. Self pairs (r = 0) add 0.
// u[k][i] += scale * Σ_j K_k(t_i − s_j) f_j    (ACCUMULATES into u).
// Newton = number of Newton steps after the hardware rsqrt estimate (AVX-512 path only):
// 2 = full double accuracy (default, direct_sum); 1 = relative error < 6e-9 per pair.
// Masked = false: the caller guarantees no target coincides with a source (saves the test).
// ND = number of density vectors sharing the pass (f: ND·src_dim arrays, u: ND·trg_dim arrays).
#include <cstddef>

#include "capsflow/fmm/simd.hpp"

namespace capsflow::fmm {

template <class Kernel, int Newton = 2, bool Masked = true, int ND = 1>
inline void p2p(const double* tx, const double* ty, const double* tz, std::size_t nt,
                const double* sx, const double* sy, const double* sz,
                const double* const* f, std::size_t ns, double* const* u, double scale) {
  using V = simd::VecD;
  constexpr int W = V::width;
  constexpr int SD = Kernel::src_dim, TD = Kernel::trg_dim;
  // ND densities share each pair's r and 1/|r|. Two target vectors per source when ND = 1 (ILP);
  // one when ND > 1 (the ND independent accumulations give the ILP, and 2·ND·TD accumulators
  // would not fit the 32 vector registers).
  constexpr int NV = ND == 1 ? 2 : 1;
  const V vscale(scale);
  std::size_t i = 0;
  for (; i + NV * W <= nt; i += NV * W) {
    V x[NV], y[NV], z[NV], a[NV][ND * TD];
    for (int v = 0; v < NV; ++v) {
      x[v] = V::load(tx + i + v * W); y[v] = V::load(ty + i + v * W); z[v] = V::load(tz + i + v * W);
      for (int k = 0; k < ND * TD; ++k) a[v][k] = V(0.0);
    }
    for (std::size_t j = 0; j < ns; ++j) {
      const V px(sx[j]), py(sy[j]), pz(sz[j]);
      V r[NV][3], ri[NV];
      for (int v = 0; v < NV; ++v) {
        r[v][0] = x[v] - px; r[v][1] = y[v] - py; r[v][2] = z[v] - pz;
        const V q = simd::fma(r[v][0], r[v][0], simd::fma(r[v][1], r[v][1], r[v][2] * r[v][2]));
        ri[v] = simd::rsqrt<Newton, Masked>(q);
      }
      for (int d = 0; d < ND; ++d) {
        V fv[SD];
        for (int k = 0; k < SD; ++k) fv[k] = V(f[d * SD + k][j]);
        for (int v = 0; v < NV; ++v) {
          V (&acc)[TD] = *reinterpret_cast<V(*)[TD]>(&a[v][d * TD]);
          Kernel::eval(acc, r[v], ri[v], fv);
        }
      }
    }
    for (int v = 0; v < NV; ++v)
      for (int k = 0; k < ND * TD; ++k) (a[v][k] * vscale).add_to(u[k] + i + v * W);
  }
  // remaining targets, one (possibly partial) vector at a time
  for (; i < nt; i += W) {
    const int m = static_cast<int>(nt - i < static_cast<std::size_t>(W) ? nt - i : W);
    const V x0 = V::load_partial(tx + i, m), y0 = V::load_partial(ty + i, m),
            z0 = V::load_partial(tz + i, m);
    V a0[ND * TD];
    for (int k = 0; k < ND * TD; ++k) a0[k] = V(0.0);
    for (std::size_t j = 0; j < ns; ++j) {
      const V px(sx[j]), py(sy[j]), pz(sz[j]);
      const V r0[3] = {x0 - px, y0 - py, z0 - pz};
      const V q0 = simd::fma(r0[0], r0[0], simd::fma(r0[1], r0[1], r0[2] * r0[2]));
      const V ri0 = simd::rsqrt<Newton, Masked>(q0);
      for (int d = 0; d < ND; ++d) {
        V fv[SD];
        for (int k = 0; k < SD; ++k) fv[k] = V(f[d * SD + k][j]);
        V (&acc)[TD] = *reinterpret_cast<V(*)[TD]>(&a0[d * TD]);
        Kernel::eval(acc, r0, ri0, fv);
      }
    }
    for (int k = 0; k < ND * TD; ++k) (a0[k] * vscale).add_to_partial(u[k] + i, m);
  }
}

/// Largest number of densities p2p_multi shares one pass between (larger counts are split).
constexpr int kMaxSharedDensities = 4;

/// p2p for nd = 1..kMaxSharedDensities densities at once: f[d*src_dim + k] = component k of
/// density d, u[d*trg_dim + k] likewise. Each density gets exactly the arithmetic of a single
/// p2p call (same operations, same order), so results equal nd single calls bit for bit.
template <class Kernel, int Newton = 2, bool Masked = true>
inline void p2p_multi(int nd, const double* tx, const double* ty, const double* tz, std::size_t nt,
                      const double* sx, const double* sy, const double* sz,
                      const double* const* f, std::size_t ns, double* const* u, double scale) {
  switch (nd) {
    case 1: p2p<Kernel, Newton, Masked, 1>(tx, ty, tz, nt, sx, sy, sz, f, ns, u, scale); break;
    case 2: p2p<Kernel, Newton, Masked, 2>(tx, ty, tz, nt, sx, sy, sz, f, ns, u, scale); break;
    case 3: p2p<Kernel, Newton, Masked, 3>(tx, ty, tz, nt, sx, sy, sz, f, ns, u, scale); break;
    case 4: p2p<Kernel, Newton, Masked, 4>(tx, ty, tz, nt, sx, sy, sz, f, ns, u, scale); break;
    default:
      for (int d0 = 0; d0 < nd; d0 += kMaxSharedDensities) {
        const int g = nd - d0 < kMaxSharedDensities ? nd - d0 : kMaxSharedDensities;
        p2p_multi<Kernel, Newton, Masked>(g, tx, ty, tz, nt, sx, sy, sz, f + d0 * Kernel::src_dim, ns,
                                          u + d0 * Kernel::trg_dim, scale);
      }
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
