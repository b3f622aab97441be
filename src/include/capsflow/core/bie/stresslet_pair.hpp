#pragma once
// A stresslet (double-layer) pair formula in the kernel form of capsflow::fmm (a stateless struct
// with src_dim, trg_dim, scale() and eval()), so that fmm::direct_sum sums it; the stresslet
// itself is fmm::Stresslet (capsflow/fmm/stresslet.hpp).
// T_ijk(r) = −6 r_i r_j r_k/|r|⁵, r = x − y (target minus source); pairs with r = 0 are skipped
// (rinv = 0 adds exactly 0). Conventions: docs/boundary-integral.md §4.7.1.
#include "capsflow/fmm/simd.hpp"

namespace capsflow {

// The matrix (1/8π) Σ_y T(r)·n, T_ijk n_k = −6 (r·n) r_i r_j/|r|⁵: per source the vector n, per
// target the 6 entries of a symmetric matrix (xx yy zz xy xz yz). The double layer of the three
// unit constants in one pass (DoubleLayer's identity term), and its near-field blocks.
struct StressletNormalPair {
  static constexpr int src_dim = 3;
  static constexpr int trg_dim = 6;
  static constexpr int homogeneity = -2;
  static constexpr const char* name = "stresslet_normal";
  static constexpr double scale() { return 1.0 / (8.0 * 3.14159265358979323846); }  // fmm::Stresslet's

  template <class V>
  static inline void eval(V (&m)[6], const V (&r)[3], const V& rinv, const V (&n)[3]) {
    const V rinv2 = rinv * rinv;
    const V rn = fmm::simd::fma(n[0], r[0], fmm::simd::fma(n[1], r[1], n[2] * r[2]));
    const V s = V(-6.0) * rn * (rinv2 * rinv2 * rinv);
    const V sx = s * r[0], sy = s * r[1];
    m[0] = fmm::simd::fma(sx, r[0], m[0]);
    m[1] = fmm::simd::fma(sy, r[1], m[1]);
    m[2] = fmm::simd::fma(s * r[2], r[2], m[2]);
    m[3] = fmm::simd::fma(sx, r[1], m[3]);
    m[4] = fmm::simd::fma(sx, r[2], m[4]);
    m[5] = fmm::simd::fma(sy, r[2], m[5]);
  }
};

}  // namespace capsflow

namespace capsflow {

// fmm::Stresslet's sum and StressletNormalPair's matrix in one pass over the pairs: per source
// (f, n) as for fmm::Stresslet; per target 9 outputs, T_ijk f_j n_k (3) then T_ijk n_k (6, xx yy zz
// xy xz yz). The double layer's set-up computes its identity term and its first application (the
// Krylov solve's initial residual) together: the pair geometry, the larger part of either, once.
struct StressletAndNormalPair {
  static constexpr int src_dim = 6;
  static constexpr int trg_dim = 9;
  static constexpr int homogeneity = -2;
  static constexpr const char* name = "stresslet_and_normal";
  static constexpr double scale() { return StressletNormalPair::scale(); }

  template <class V>
  static inline void eval(V (&u)[9], const V (&r)[3], const V& rinv, const V (&d)[6]) {
    const V rinv2 = rinv * rinv;
    const V rf = fmm::simd::fma(r[0], d[0], fmm::simd::fma(r[1], d[1], r[2] * d[2]));
    const V rn = fmm::simd::fma(r[0], d[3], fmm::simd::fma(r[1], d[4], r[2] * d[5]));
    const V s = V(-6.0) * rn * (rinv2 * rinv2 * rinv);
    const V c = s * rf;
    u[0] = fmm::simd::fma(c, r[0], u[0]);
    u[1] = fmm::simd::fma(c, r[1], u[1]);
    u[2] = fmm::simd::fma(c, r[2], u[2]);
    const V sx = s * r[0], sy = s * r[1];
    u[3] = fmm::simd::fma(sx, r[0], u[3]);
    u[4] = fmm::simd::fma(sy, r[1], u[4]);
    u[5] = fmm::simd::fma(s * r[2], r[2], u[5]);
    u[6] = fmm::simd::fma(sx, r[1], u[6]);
    u[7] = fmm::simd::fma(sx, r[2], u[7]);
    u[8] = fmm::simd::fma(sy, r[2], u[8]);
  }
};

}  // namespace capsflow
