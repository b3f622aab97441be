#pragma once
// Eight Stokeslet terms stored lane by lane (structure of arrays), summed at one target with
// capsflow::fmm's SIMD vector type: Σ_j G(x − y_j) f_j over a range of lanes, unscaled (the
// caller multiplies by fmm::Stokeslet::scale()).
//
// The single layer's near field adds, for every element near a node, a fixed set of rule points
// of that element (7-point ring rule, 3-point band rule) minus its far-field terms. Those sets
// are the same for every node that sees the element, so they are laid out once per element and
// evaluation in blocks of eight lanes, and each node streams its elements' blocks through full
// vector loads — instead of gathering the terms one by one (StokesletBatch, which stays for the
// curved elements' Duffy points, whose count varies).
#include <algorithm>

#include "capsflow/core/types.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow {

struct alignas(64) StokesletBlock {
  static constexpr int kLanes = 8;
  double y[3][kLanes] = {};  // source positions (unused lanes: 0)
  double f[3][kLanes] = {};  // forces (unused lanes: 0, so they add exactly 0)

  void set(int lane, const Vec3& pos, const Vec3& force) {
    for (int d = 0; d < 3; ++d) y[d][lane] = pos[d], f[d][lane] = force[d];
  }

  // u += Σ_{j in [first, first + count)} G(x − y_j) f_j, lane by lane in u (reduce with lane_sum).
  template <class V>
  void accumulate(const double (&x)[3], int first, int count, V (&u)[3]) const {
    constexpr int W = V::width;
    const V xv[3] = {V(x[0]), V(x[1]), V(x[2])};
    for (int j = first; j < first + count; j += W) {
      const int m = std::min(W, first + count - j);
      V r[3], g[3];
      for (int d = 0; d < 3; ++d) {
        r[d] = xv[d] - (m == W ? V::load(&y[d][j]) : V::load_partial(&y[d][j], m));
        g[d] = m == W ? V::load(&f[d][j]) : V::load_partial(&f[d][j], m);
      }
      // Masked: a lane at the target itself (r = 0, only ever an empty lane) adds 0, not NaN.
      const V r2 = fmm::simd::fma(r[0], r[0], fmm::simd::fma(r[1], r[1], r[2] * r[2]));
      fmm::Stokeslet::eval(u, r, fmm::simd::rsqrt<2, true>(r2), g);
    }
  }
};

// The lanes of u[0..2] added up: the vector Σ.
template <class V>
Vec3 lane_sum(const V (&u)[3]) {
  constexpr int W = V::width;
  double b[3][W];
  for (int d = 0; d < 3; ++d) u[d].store(b[d]);
  Vec3 out = Vec3::Zero();
  for (int k = 0; k < W; ++k) out += Vec3(b[0][k], b[1][k], b[2][k]);
  return out;
}

}  // namespace capsflow
