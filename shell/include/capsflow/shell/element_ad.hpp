#pragma once
// Exact element gradient and Hessian by second-order forward automatic differentiation of the
// templated element energy (element.hpp), with respect to the 15 element DOFs
// (x_0, x_1, x_2, w_0, w_1, w_2): positions and rotation increments w_p = (w1, w2) in the nodal
// triads, evaluated at w = 0 with d_p(w) = exp([w1 t1 + w2 t2]x) d_p (2nd-order expansion, exact
// for first and second derivatives at w = 0). Used by the forward static mode and by tests as an
// oracle for the hand-coded kernels. Cost ~100x the hand-coded kernel: not for the hot path.
#include "capsflow/shell/element.hpp"
#include "capsflow/shell/hyperdual.hpp"

namespace capsflow::shell {

struct ElementHessian {
  double E = 0;
  double g[15];
  double H[15][15];
};

inline void element_hessian(const ElementRef& R, const MembraneLaw& law, const Vec3 x[3],
                            const Vec3 d[3], const Vec3 t1[3], const Vec3 t2[3], ElementHessian& out,
                            bool with_membrane = true) {
  using H = Hyper<15>;
  H xs[3][3], ds[3][3];
  for (int a = 0; a < 3; ++a) {
    for (int c = 0; c < 3; ++c) xs[a][c] = H::variable(x[a][c], 3 * a + c);
    const H w1 = H::variable(0.0, 9 + 2 * a), w2 = H::variable(0.0, 10 + 2 * a);
    H w[3], dd[3];
    for (int c = 0; c < 3; ++c) {
      w[c] = w1 * t1[a][c] + w2 * t2[a][c];
      dd[c] = H(d[a][c]);
    }
    auto cross = [](const H* p, const H* q, H* r) {
      r[0] = p[1] * q[2] - p[2] * q[1];
      r[1] = p[2] * q[0] - p[0] * q[2];
      r[2] = p[0] * q[1] - p[1] * q[0];
    };
    H wd[3], wwd[3];
    cross(w, dd, wd);
    cross(w, wd, wwd);
    for (int c = 0; c < 3; ++c) ds[a][c] = dd[c] + wd[c] + 0.5 * wwd[c];
  }
  H e[3];
  element_energy_t(R, law, xs, ds, e);
  const H E = with_membrane ? e[0] + e[1] + e[2] : e[1] + e[2];
  out.E = E.v;
  for (int i = 0; i < 15; ++i) {
    out.g[i] = E.g[i];
    for (int j = 0; j < 15; ++j) out.H[i][j] = E.hess(i, j);
  }
}

}  // namespace capsflow::shell
