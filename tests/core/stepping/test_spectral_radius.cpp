// The spectral-radius power iteration (stepping/spectral_radius.hpp) on right-hand sides whose
// Jacobian is known: linear diagonal systems and a nonlinear one.
#include <gtest/gtest.h>

#include <vector>

#include "capsflow/core/stepping/spectral_radius.hpp"

using namespace capsflow;

namespace {
// y' = −diag(λ) y, three components per node with the node's λ.
FunctionRhs diagonal(const Eigen::VectorXd& lambda) {
  return FunctionRhs([lambda](const Points& y, Points& v) {
    v.resize(y.rows(), 3);
    for (Eigen::Index i = 0; i < y.rows(); ++i) v.row(i) = -lambda[i] * y.row(i);
  });
}
Points state(Eigen::Index n) {
  Points y(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) y.row(i) << 1.0 + 0.1 * i, 0.5, -0.3;
  return y;
}
}  // namespace

TEST(SpectralRadius, ConvergesFromBelowToTheLargestEigenvalue) {
  // λ = 1…50 and one stiff mode at 1000: a gap of 20, so the iteration converges in a few steps.
  Eigen::VectorXd lambda = Eigen::VectorXd::LinSpaced(50, 1, 50);
  lambda[17] = 1000;
  FunctionRhs f = diagonal(lambda);
  const Points y = state(50);
  Points fy;
  f(y, fy);
  SpectralRadiusEstimator power;
  const SpectralRadiusEstimator::Result r = power.estimate(f, y, fy);
  ASSERT_TRUE(r.converged);
  EXPECT_LE(r.sigma, 1000 * (1 + 1e-6));  // from below (difference quotient of a linear F: exact up to round-off √ε)
  EXPECT_GE(r.sigma, 1000 * 0.99);        // the stopping test: successive estimates within rel_tol = 1 %
  // Warm-started from the last direction, a refresh costs a few evaluations (the point of keeping it).
  const SpectralRadiusEstimator::Result again = power.estimate(f, y, fy);
  EXPECT_TRUE(again.converged);
  EXPECT_LE(again.evaluations, 3);
  EXPECT_LT(again.evaluations, r.evaluations);
}

TEST(SpectralRadius, SeesTheLinearisationOfANonlinearRightHandSide) {
  // F(y) = −y³ componentwise: J = −3 diag(y²), ρ = 3 max y² = 3 · 2.5² at the node below.
  FunctionRhs f([](const Points& y, Points& v) { v = -y.array().cube().matrix(); });
  Points y = state(10);
  y(4, 1) = 2.5;
  Points fy;
  f(y, fy);
  SpectralRadiusEstimator power;
  const SpectralRadiusEstimator::Result r = power.estimate(f, y, fy);
  ASSERT_TRUE(r.converged);
  EXPECT_NEAR(r.sigma, 3 * 2.5 * 2.5, 0.01 * 3 * 2.5 * 2.5);  // rel_tol 1 %; δ = √ε|y| adds O(δ) only
}

TEST(SpectralRadius, ZeroAtAConstantRightHandSideAndProbesAreHinted) {
  // F constant: no direction changes F, σ = 0 after one evaluation (an equilibrium of F ≡ 0 too).
  std::vector<EvaluationHint::Role> roles;
  struct Recording final : RightHandSide {
    std::vector<EvaluationHint::Role>* roles;
    explicit Recording(std::vector<EvaluationHint::Role>* r) : roles(r) {}
    void evaluate(const Points& y, Points& v, const EvaluationHint& h) override {
      roles->push_back(h.role);
      v = Points::Constant(y.rows(), 3, 0.25);
    }
  } f(&roles);
  const Points y = state(5);
  Points fy;
  f(y, fy);
  roles.clear();
  SpectralRadiusEstimator power;
  const SpectralRadiusEstimator::Result r = power.estimate(f, y, fy);
  EXPECT_EQ(r.sigma, 0.0);
  EXPECT_EQ(r.evaluations, 1);
  ASSERT_EQ(roles.size(), 1u);
  EXPECT_EQ(roles[0], EvaluationHint::Role::Probe);  // off the trajectory: a right-hand side may keep its warm start
}
