#pragma once
// The Stokeslet sum Σ G(r) f = Σ f/|r| + r (r·f)/|r|³ in long double, written out independently of
// fmm::Stokeslet, with r = 0 skipped: the oracle of the near-field batch and block tests.
#include <cmath>
#include <utility>
#include <vector>

#include "capsflow/core/types.hpp"

namespace capsflow::test {

inline Vec3 stokeslet_reference_sum(const std::vector<std::pair<Vec3, Vec3>>& terms) {  // (r, f)
  long double u[3] = {0, 0, 0};
  for (const auto& [r, f] : terms) {
    const long double r2 = static_cast<long double>(r.squaredNorm());
    if (r2 == 0) continue;
    const long double inv = 1.0L / std::sqrt(r2);
    const long double rf = static_cast<long double>(r.dot(f));
    for (int k = 0; k < 3; ++k) u[k] += inv * f[k] + rf * inv * inv * inv * r[k];
  }
  return {static_cast<double>(u[0]), static_cast<double>(u[1]), static_cast<double>(u[2])};
}

}  // namespace capsflow::test
