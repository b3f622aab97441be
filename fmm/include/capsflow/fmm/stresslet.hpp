#pragma once
// capsflow::fmm::Stresslet — the free-space stresslet: the kernel of the Stokes double layer.
//
// Conventions (pinned by tests/fmm/test_kernels.cpp, StressletConvention.*):
//   u_i(x) = (1/8π) Σ_y T_ijk(r) f_j n_k,   T_ijk(r) = −6 r_i r_j r_k / |r|^5,   r = x − y (target minus source).
//   - Densities: 6 components per source, f (3) then n (3): f0 f1 f2 n0 n1 n2. The surface double
//     layer passes f = w·u(y) (quadrature weight folded in) and n = n(y); any two 3-vectors work,
//     the sum is bilinear in (f, n). Outputs: 3 components per target.
//   - Pairs with r = 0 (a target that coincides with a source) are skipped: they contribute 0.
//   - Homogeneous of degree −2: T(a r) = T(r)/a².
//   - Closed surface S with outward normal n and f = c·dS (c constant): u = c inside S, 0 outside
//     (the double-layer identity in this sign convention; tested).
//   - Viscosity does not enter the double layer.
// eval() accumulates the unscaled T_ijk(r) f_j n_k = −6 (r·f)(r·n) r_i/|r|^5; scale() = 1/(8π), the
// Stokeslet's, is applied once by the caller (the interface src/bie's double layer codes against).
//
// In the FMM the upward equivalent densities are Stokeslets plus point sources (StokesletSource),
// kept free of net force: the trace part of f⊗n emits a net flux that Stokeslets alone cannot
// represent (docs/fmm.md §3.10). Only the source-side steps (P2M, P2L and the direct near field)
// evaluate this kernel; the downward pass uses Stokeslet equivalent densities.
#include "capsflow/fmm/simd.hpp"
#include "capsflow/fmm/stokeslet.hpp"
#include "capsflow/fmm/stokeslet_source.hpp"

namespace capsflow::fmm {

struct Stresslet {
  static constexpr int src_dim = 6;
  static constexpr int trg_dim = 3;
  static constexpr int homogeneity = -2;
  static constexpr const char* name = "stresslet";
  static constexpr double scale() { return 1.0 / (8.0 * 3.14159265358979323846); }
  using UpwardEquivalent = StokesletSource;
  using DownwardEquivalent = Stokeslet;
  /// T_ijk f_j n_k exerts no net force (a force dipole): its upward densities are kept force-free
  static constexpr bool net_force_free = true;

  template <class V>
  static inline void eval(V (&u)[3], const V (&r)[3], const V& rinv, const V (&d)[6]) {
    const V rf = simd::fma(r[0], d[0], simd::fma(r[1], d[1], r[2] * d[2]));
    const V rn = simd::fma(r[0], d[3], simd::fma(r[1], d[4], r[2] * d[5]));
    const V rinv2 = rinv * rinv;
    const V c = V(-6.0) * (rf * rn) * (rinv2 * rinv2 * rinv);
    u[0] = simd::fma(c, r[0], u[0]);
    u[1] = simd::fma(c, r[1], u[1]);
    u[2] = simd::fma(c, r[2], u[2]);
  }
};

}  // namespace capsflow::fmm
