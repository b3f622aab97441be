#include "capsflow/core/theory/small_deformation.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace capsflow::theory {

Mat2 viscous_resistance(double lambda) {
  // docs/small-deformation.md §3: outer Lamb fields (stresslet, potential quadrupole) and inner
  // ones (pure strain, Lamb's r² field) matched to the surface velocity.
  Mat2 R;
  R << 6 + 6.5 * lambda, -(3 + 4.5 * lambda),
      -(2 + 3 * lambda), 5 * (1 + lambda);
  return R;
}

Mat2 membrane_stiffness(double G, double nu) {
  const double K = G * (1 + nu) / (1 - nu);  // area-dilatation modulus (docs §2)
  Mat2 S;
  S << 4 * K, -6 * K,
      -4 * K, 4 * G + 6 * K;
  return S;
}

SmallDeformation::SmallDeformation(double G, double nu, double lambda)
    : lambda_(lambda), R_(viscous_resistance(lambda)), K_(membrane_stiffness(G, nu)) {
  if (!(std::isfinite(G) && G > 0)) throw std::invalid_argument("SmallDeformation: G_s must be > 0");
  if (!(nu > -1 && nu < 1)) throw std::invalid_argument("SmallDeformation: ν_s must lie in (−1, 1)");
  if (!(std::isfinite(lambda) && lambda > 0)) throw std::invalid_argument("SmallDeformation: λ must be > 0");
  // R y' = f − K y, y(0) = 0  ⇒  y = y∞ − exp(−A t) y∞ with A = R⁻¹K, y∞ = K⁻¹f. A's eigenvalues
  // are real, distinct and positive (R and K are symmetric positive definite in the modes' L²
  // product, docs §4), so exp(−A t) = Σ_k e^{−s_k t} P_k with the spectral projectors
  // P_k = (A − s_j I)/(s_k − s_j).
  const Vec2 f = Vec2::Constant(kRigidSphereTraction);
  const Vec2 y_inf = K_.lu().solve(f);
  c_inf_ = y_inf[0];
  const Mat2 A = R_.lu().solve(K_);
  const double tr = A.trace(), det = A.determinant();
  const double root = std::sqrt(tr * tr - 4 * det);
  rates_ = {0.5 * (tr - root), 0.5 * (tr + root)};
  for (int k = 0; k < 2; ++k) {
    const double sj = rates_[1 - k];
    const Vec2 Py = (A * y_inf - sj * y_inf) / (rates_[k] - sj);
    weights_[k] = Py[0] / c_inf_;
  }
}

double SmallDeformation::amplitude(double t) const {
  return c_inf_ * (1 - weights_[0] * std::exp(-rates_[0] * t) - weights_[1] * std::exp(-rates_[1] * t));
}

double SmallDeformation::initial_rate() const { return mode_rates(Vec2::Zero())[0]; }

double SmallDeformation::relaxation_time() const {
  return weights_[0] / rates_[0] + weights_[1] / rates_[1];
}

Vec2 SmallDeformation::mode_rates(const Vec2& y) const {
  return R_.lu().solve(Vec2::Constant(kRigidSphereTraction) - K_ * y);
}

InPlaneShape SmallDeformation::in_plane_shape(const Mat3& L, const FlowPlane& plane, double t) const {
  const Mat3 E = 0.5 * (L + L.transpose());
  Eigen::Matrix<double, 3, 2> P;
  P << plane.e1, plane.e2;
  const Eigen::SelfAdjointEigenSolver<Mat2> es(P.transpose() * E * P);
  const double c = amplitude(t);
  InPlaneShape s;
  s.a = 1 + c * es.eigenvalues()[1];
  s.b = 1 + c * es.eigenvalues()[0];
  s.D = 0.5 * c * (es.eigenvalues()[1] - es.eigenvalues()[0]);
  const Vec2 major = es.eigenvectors().col(1);
  s.theta = std::atan2(major.y(), major.x());  // as geometry/flow_plane: in (−π/2, π/2]
  if (s.theta > M_PI / 2) s.theta -= M_PI;
  if (s.theta <= -M_PI / 2) s.theta += M_PI;
  return s;
}

double SmallDeformation::tank_treading_rate(const Mat3& L, const FlowPlane& plane) {
  const Vec3 curl(L(2, 1) - L(1, 2), L(0, 2) - L(2, 0), L(1, 0) - L(0, 1));
  return plane.sense * 0.5 * curl.dot(plane.normal);
}

Vec3 SmallDeformation::coordinate_taylor(const Mat3& L, double t) const {
  const Mat3 E = 0.5 * (L + L.transpose());
  if (!E.isDiagonal(1e-14 * (1 + E.norm()))) return Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  const double c = amplitude(t);
  return 0.5 * c * Vec3(E(0, 0) - E(1, 1), E(0, 0) - E(2, 2), E(1, 1) - E(2, 2));
}

Vec3 initial_surface_velocity(const Mat3& L, double lambda, const Vec3& x) {
  const Mat3 E = 0.5 * (L + L.transpose()), W = 0.5 * (L - L.transpose());
  return W * x + 5 / (2 * lambda + 3) * (E * x);
}

}  // namespace capsflow::theory
