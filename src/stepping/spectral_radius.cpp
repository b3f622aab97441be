#include "capsflow/core/stepping/spectral_radius.hpp"

#include <cmath>
#include <limits>

namespace capsflow {

SpectralRadiusEstimator::Result SpectralRadiusEstimator::estimate(RightHandSide& f, const Points& y, const Points& fy,
                                                                  int max_iter, double rel_tol) {
  Result r;
  const double eps = std::numeric_limits<double>::epsilon();
  const double ynorm = y.norm();
  const double delta = ynorm > 0 ? std::sqrt(eps) * ynorm : std::sqrt(eps);
  // Start from the last direction, else from F(y) (rich in the stiff modes a step excites), else
  // from a fixed pattern (F(y) = 0 at an equilibrium).
  if (dir_.rows() != y.rows() || !(dir_.norm() > 0)) dir_ = fy;
  if (!(dir_.norm() > 0)) {
    dir_.resize(y.rows(), 3);
    for (Eigen::Index i = 0; i < y.rows(); ++i)
      dir_.row(i) << std::sin(1.0 + i), std::cos(2.0 + 3.0 * i), std::sin(5.0 * i + 0.5);
  }
  double sigma_prev = 0;
  for (int it = 0; it < max_iter; ++it) {
    yv_.noalias() = y + (delta / dir_.norm()) * dir_;
    f.evaluate(yv_, fv_, {EvaluationHint::Role::Probe, 0});
    ++r.evaluations;
    dir_.noalias() = fv_ - fy;
    const double dnorm = dir_.norm();
    r.sigma = dnorm / delta;
    if (!(dnorm > 0)) break;  // F is locally constant along the direction: σ = 0
    if (it > 0 && std::abs(r.sigma - sigma_prev) <= rel_tol * r.sigma) {
      r.converged = true;
      break;
    }
    sigma_prev = r.sigma;
  }
  return r;
}

}  // namespace capsflow
