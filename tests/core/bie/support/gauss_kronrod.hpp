#pragma once
// Independent references for the singular element tests (single and double layer): adaptive
// Gauss–Kronrod (7–15) quadrature of a 3×9-matrix-valued function, and integrals over the
// parameter triangle of an element in polar coordinates about its vertex x0.
#include <array>
#include <cmath>
#include <functional>

#include <Eigen/Core>

#include "capsflow/core/bie/quadrature.hpp"

namespace capsflow::testing {

// Adaptive Gauss–Kronrod (7–15) of a matrix-valued function on [a, b] to absolute tolerance.
using MatFn = std::function<Eigen::Matrix<double, 3, 9>(double)>;
inline Eigen::Matrix<double, 3, 9> gauss_kronrod(const MatFn& f, double a, double b, double tol, int depth = 0) {
  static const double xk[8] = {0.991455371120812639, 0.949107912342758525, 0.864864423359769073, 0.741531185599394440,
                               0.586087235467691130, 0.405845151377397167, 0.207784955007898468, 0.0};
  static const double wk[8] = {0.022935322010529225, 0.063092092629978553, 0.104790010322250184, 0.140653259715525919,
                               0.169004726639267903, 0.190350578064785410, 0.204432940075298892, 0.209482141084727828};
  static const double wg[4] = {0.129484966168869693, 0.279705391489276668, 0.381830050505118945, 0.417959183673469388};
  const double c = 0.5 * (a + b), h = 0.5 * (b - a);
  Eigen::Matrix<double, 3, 9> k = wk[7] * f(c), g = wg[3] * f(c);
  for (int i = 0; i < 7; ++i) {
    const auto fp = f(c + h * xk[i]), fm = f(c - h * xk[i]);
    k += wk[i] * (fp + fm);
    if (i % 2 == 1) g += wg[i / 2] * (fp + fm);
  }
  k *= h, g *= h;
  if ((k - g).cwiseAbs().maxCoeff() < tol || depth > 30) return k;
  return gauss_kronrod(f, a, c, tol / 2, depth + 1) + gauss_kronrod(f, c, b, tol / 2, depth + 1);
}

// Σ_k-resolved ∫ K(ξ, η, ρ) φ_k(ξ, η) dρ dφ over the parameter triangle ξ, η ≥ 0, ξ + η ≤ 1 in
// polar coordinates (ξ, η) = ρ (cos φ, sin φ): K returns the 3×3 integrand times the polar
// Jacobian ρ (which cancels the 1/|r| of a weakly singular kernel at x0). ρ by 24-point Gauss,
// φ adaptively to 1e-14: independent of the Duffy map of the production code.
template <class Kernel>
std::array<Mat3, 3> polar_parameter_integral(Kernel&& K, double tol = 1e-14) {
  const GaussLegendre gl(24);
  auto f = [&](double phi) {
    const double c = std::cos(phi), s = std::sin(phi), rmax = 1.0 / (c + s);
    Eigen::Matrix<double, 3, 9> out = Eigen::Matrix<double, 3, 9>::Zero();
    for (size_t q = 0; q < gl.x.size(); ++q) {
      const double rho = gl.x[q] * rmax, w = gl.w[q] * rmax;
      const double xi = rho * c, eta = rho * s;
      const Mat3 Kw = w * K(xi, eta, rho);
      const double phik[3] = {1 - xi - eta, xi, eta};
      for (int k = 0; k < 3; ++k) out.block<3, 3>(0, 3 * k) += phik[k] * Kw;
    }
    return out;
  };
  const Eigen::Matrix<double, 3, 9> I = gauss_kronrod(f, 0.0, M_PI / 2, tol);
  return {I.block<3, 3>(0, 0), I.block<3, 3>(0, 3), I.block<3, 3>(0, 6)};
}

}  // namespace capsflow::testing
