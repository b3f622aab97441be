#pragma once
// capsflow::fmm::Stokeslet — the free-space Stokeslet (Oseen tensor), viscosity mu = 1.
//
// Conventions (pinned by tests/fmm/test_kernels.cpp):
//   u(x_i) = (1/8π) Σ_j G(x_i − y_j) f_j,   G(r) = I/|r| + r r^T/|r|^3,   r = x − y (target minus source).
//   - Densities: 3 components per source (a point force f_j); outputs: 3 components per target.
//   - Pairs with r = 0 (a target that coincides with a source) are skipped: they contribute 0.
//   - Homogeneous of degree −1: G(a r) = G(r)/a, so the FMM operators are built once per order.
//   - For viscosity mu divide the result by mu.
//
// A kernel is a stateless struct: component counts, homogeneity degree, scale factor, and one pair
// formula templated on the value type V (double, or simd::VecD). eval() ACCUMULATES the unscaled
// contribution of one source into u; the caller multiplies by scale() once at the end.
// rinv = 1/|r|, or 0 for r = 0 (the caller's mask; the formula then adds exactly 0).
#include "capsflow/fmm/simd.hpp"

namespace capsflow::fmm {

struct Stokeslet {
  static constexpr int src_dim = 3;
  static constexpr int trg_dim = 3;
  static constexpr int homogeneity = -1;
  static constexpr const char* name = "stokeslet";
  static constexpr double scale() { return 1.0 / (8.0 * 3.14159265358979323846); }

  template <class V>
  static inline void eval(V (&u)[3], const V (&r)[3], const V& rinv, const V (&f)[3]) {
    const V rinv2 = rinv * rinv;
    const V fr = simd::fma(f[0], r[0], simd::fma(f[1], r[1], f[2] * r[2])) * rinv2;
    u[0] = simd::fma(rinv, simd::fma(r[0], fr, f[0]), u[0]);
    u[1] = simd::fma(rinv, simd::fma(r[1], fr, f[1]), u[1]);
    u[2] = simd::fma(rinv, simd::fma(r[2], fr, f[2]), u[2]);
  }
};

}  // namespace capsflow::fmm
