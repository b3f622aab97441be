#pragma once
// capsflow::fmm::Laplace — the 3-D Laplace single layer, used to test the FMM machinery on a
// second kernel.
//
// Conventions (pinned by tests/fmm/test_kernels.cpp):
//   u(x_i) = (1/4π) Σ_j q_j / |x_i − y_j|,  1 density and 1 output component per point,
//   pairs with x_i = y_j skipped; homogeneous of degree −1.
// eval() accumulates the unscaled contribution (rinv·q); the caller applies scale() once.
#include "capsflow/fmm/simd.hpp"

namespace capsflow::fmm {

struct Laplace {
  static constexpr int src_dim = 1;
  static constexpr int trg_dim = 1;
  static constexpr int homogeneity = -1;
  static constexpr const char* name = "laplace";
  static constexpr double scale() { return 1.0 / (4.0 * 3.14159265358979323846); }

  template <class V>
  static inline void eval(V (&u)[1], const V (&)[3], const V& rinv, const V (&q)[1]) {
    u[0] = simd::fma(rinv, q[0], u[0]);
  }
};

}  // namespace capsflow::fmm
