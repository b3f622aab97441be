#pragma once
// capsflow::fmm::StokesletSource — a Stokeslet plus a point source: the upward equivalent density
// of the stresslet FMM (docs/fmm.md §3.10). Not a physical sum of capsflow; an FMM internal.
//
// Conventions (pinned by tests/fmm/test_kernels.cpp, StokesletSourceConvention.*):
//   u(x_i) = (1/8π) Σ_j [ G(r) f_j + q_j r/|r|^3 ],   G as in stokeslet.hpp,   r = x_i − y_j.
//   - Densities: 4 components per source (f0 f1 f2 q); outputs: 3 per target; r = 0 skipped.
//   - Why the source: the field of stresslets in a box carries the net flux of the trace part of
//     f⊗n through any surface around the box; a layer of Stokeslets has zero flux, a source
//     q r/|r|^3 has flux 4π q.
//   - Mixed homogeneity: the f columns are of degree −1 (`homogeneity`), the q column of degree
//     −2 = homogeneity + degree_shift(3). The FMM stores q of a box of half-width ρ as q/ρ so that
//     operators built for half-width 1 serve every level (fmm_impl.hpp, operators.hpp).
// eval() accumulates the unscaled G f + q r/|r|^3; the caller applies scale() once.
#include "capsflow/fmm/simd.hpp"

namespace capsflow::fmm {

struct StokesletSource {
  static constexpr int src_dim = 4;
  static constexpr int trg_dim = 3;
  static constexpr int homogeneity = -1;
  static constexpr const char* name = "stokeslet_source";
  static constexpr double scale() { return 1.0 / (8.0 * 3.14159265358979323846); }
  /// degree of density component b minus `homogeneity` (0 for the force, −1 for the source)
  static constexpr int degree_shift(int b) { return b == 3 ? -1 : 0; }

  template <class V>
  static inline void eval(V (&u)[3], const V (&r)[3], const V& rinv, const V (&d)[4]) {
    // G f + q r/|r|^3 = (f + r (f·r + q)/|r|^2)/|r|: the Stokeslet's formula with f·r + q
    const V s = (simd::fma(d[0], r[0], simd::fma(d[1], r[1], simd::fma(d[2], r[2], d[3])))) * (rinv * rinv);
    u[0] = simd::fma(rinv, simd::fma(r[0], s, d[0]), u[0]);
    u[1] = simd::fma(rinv, simd::fma(r[1], s, d[1]), u[1]);
    u[2] = simd::fma(rinv, simd::fma(r[2], s, d[2]), u[2]);
  }
};

}  // namespace capsflow::fmm
