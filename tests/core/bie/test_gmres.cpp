// Restarted GMRES in a weighted inner product against a dense LU solve.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include "capsflow/core/bie/gmres.hpp"

using namespace capsflow;

TEST(Gmres, SolvesNonSymmetricSystemInWeightedNorm) {
  // A = I + 0.4 · random (non-symmetric, eigenvalues in a disc about 1 of radius < 1).
  const int n = 60;
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(n, n), C(n, 4);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) += 0.4 * U(gen) / std::sqrt(n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 4; ++j) C(i, j) = U(gen);
  Eigen::VectorXd b(n), w(n);
  for (int i = 0; i < n; ++i) b[i] = U(gen), w[i] = 0.5 + std::abs(U(gen));
  const Eigen::VectorXd exact = A.partialPivLu().solve(b);
  for (int restart : {5, 60}) {
    Eigen::VectorXd x = Eigen::VectorXd::Zero(n), aux = Eigen::VectorXd::Zero(4);
    GmresOptions opt;
    opt.tolerance = 1e-12;
    opt.restart = restart;
    const GmresOperator op = [&](const Eigen::VectorXd& v, Eigen::VectorXd& y, Eigen::VectorXd* a, double) {
      y = A * v;
      if (a) *a = C.transpose() * v;  // any linear image of the iterate
      return 0.0;
    };
    const GmresResult r = gmres(op, b, x, w, std::sqrt((w.array() * b.array().square()).sum()), opt, &aux);
    ASSERT_TRUE(r.converged) << "restart " << restart;
    // Residual 1e-12 ‖b‖ and ‖A⁻¹‖ = O(1): the error is ~1e-12 ‖x‖; 1e-10 leaves round-off margin.
    EXPECT_LT((x - exact).norm(), 1e-10 * exact.norm()) << "restart " << restart;
    EXPECT_LT((aux - C.transpose() * x).norm(), 1e-10 * (C.transpose() * x).norm()) << "restart " << restart;
    // Unrestarted GMRES on a 60-unknown system terminates in at most 60 steps (exact arithmetic).
    if (restart == 60) {
      EXPECT_LE(r.iterations, 60);
    }
  }
}

// Inexact applications: an operator that errs by a share of its allowance (a random direction
// scaled to share · allowed_error · ‖v‖) and says so. GMRES must stop only when the recurrence's
// residual plus the committed errors' bound Σ |z_k| e_k is within the target, so the TRUE residual
// is within the target whatever the share — while the allowances grow as the residual falls (the
// point of it). share = 1 commits everything it is allowed, which on this operator (σ_min ≈ 0.4)
// makes the bound reach half the target and forces restarts with a smaller margin; 0.01 needs none.
TEST(Gmres, TheTrueResidualMeetsTheTargetWhateverTheInexactStepsCommit) {
  const int n = 80;
  std::mt19937 gen(5);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) += 0.5 * U(gen) / std::sqrt(n);
  Eigen::VectorXd b(n), w(n);
  for (int i = 0; i < n; ++i) b[i] = U(gen), w[i] = 0.5 + std::abs(U(gen));
  auto wnorm = [&](const Eigen::VectorXd& v) { return std::sqrt((w.array() * v.array().square()).sum()); };
  for (double share : {1.0, 0.25, 0.01})
    for (double tol : {1e-4, 1e-8}) {
      std::vector<double> allowed;
      const GmresOperator op = [&](const Eigen::VectorXd& v, Eigen::VectorXd& y, Eigen::VectorXd*, double err) {
        y = A * v;
        allowed.push_back(err);
        if (err <= 0) return 0.0;
        Eigen::VectorXd e(n);
        for (int i = 0; i < n; ++i) e[i] = U(gen);
        y += (share * err * wnorm(v) / wnorm(e)) * e;
        return share * err;
      };
      Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
      GmresOptions opt;
      opt.tolerance = tol;
      const double scale = wnorm(b);
      const GmresResult r = gmres(op, b, x, w, scale, opt);
      ASSERT_TRUE(r.converged) << share << " " << tol;
      // The bound is rigorous: 1e-9 relative slack for round-off in the recurrence.
      EXPECT_LT(wnorm(b - A * x), (1 + 1e-9) * tol * scale) << share << " " << tol;
      EXPECT_LE(wnorm(b - A * x), r.residual * (1 + 1e-9)) << share << " " << tol;  // residual is a bound
      EXPECT_EQ(allowed.front(), 0.0);  // the initial residual is asked exactly
      if (share == 1.0) {
        EXPECT_GT(r.bound_restarts, 0) << tol;  // the committed errors did reach half the target
      } else if (share == 0.01) {
        EXPECT_EQ(r.bound_restarts, 0) << share << " " << tol;
        // The last allowance is ≥ 10× the first Krylov vector's: the residual fell by ≥ 10 meanwhile.
        ASSERT_GE(allowed.size(), 3u);
        EXPECT_GT(allowed.back(), 10 * allowed[1]) << share << " " << tol;
      }
    }
}
