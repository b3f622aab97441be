// Restarted GMRES in a weighted inner product against a dense LU solve.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

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
    const GmresOperator op = [&](const Eigen::VectorXd& v, Eigen::VectorXd& y, Eigen::VectorXd* a) {
      y = A * v;
      if (a) *a = C.transpose() * v;  // any linear image of the iterate
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
