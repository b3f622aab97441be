// BlockPcg (shell/src/pcg.cpp), the one PCG of capsflow: against a direct solve on SPD block
// systems, its iteration count against the CG bound, what the block-Jacobi preconditioner buys,
// several right-hand sides, warm starts, negative curvature, thread-count independence.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdlib>
#include <random>
#include <vector>

#include "capsflow/shell/pcg.hpp"

using namespace capsflow::shell;

namespace {

// A random SPD matrix of nb blocks of size bs, shaped like the wall's tangents: a ring of
// neighbouring blocks plus a few random links, each coupling (e_i − e_j)(e_i − e_j)ᵀ ⊗ S with S SPD
// (PSD in sum), plus SPD diagonal blocks whose eigenvalues are `spread` apart with a random
// orientation and whose scale varies by `scales` between blocks. `block_diagonal` drops the links.
SpMatR random_block_spd(int nb, int bs, double spread, double scales, unsigned seed,
                        bool block_diagonal = false) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  auto random_spd = [&](double lo, double hi) {
    const Eigen::MatrixXd Q = Eigen::HouseholderQR<Eigen::MatrixXd>(Eigen::MatrixXd::Random(bs, bs)).householderQ();
    Eigen::VectorXd ev(bs);
    for (int k = 0; k < bs; ++k) ev[k] = lo * std::pow(hi / lo, bs == 1 ? 1.0 : double(k) / (bs - 1));
    return Eigen::MatrixXd(Q * ev.asDiagonal() * Q.transpose());
  };
  std::srand(seed);  // Eigen's Random uses rand()
  std::vector<Eigen::Triplet<double>> trip;  // duplicates are summed
  auto add = [&](int bi, int bj, const Eigen::MatrixXd& M) {
    for (int k = 0; k < bs; ++k)
      for (int l = 0; l < bs; ++l) trip.emplace_back(bi * bs + k, bj * bs + l, M(k, l));
  };
  for (int b = 0; b < nb; ++b) add(b, b, std::pow(scales, U(rng)) * random_spd(1.0, spread));
  if (!block_diagonal) {
    auto link = [&](int i, int j) {
      const Eigen::MatrixXd S = random_spd(0.2, 1.0);
      add(i, i, S);
      add(j, j, S);
      add(i, j, -S);
      add(j, i, -S);
    };
    for (int b = 0; b < nb; ++b) link(b, (b + 1) % nb);
    for (int k = 0; k < nb / 4; ++k) {
      const int i = static_cast<int>(U(rng) * nb) % nb, j = static_cast<int>(U(rng) * nb) % nb;
      if (i != j) link(i, j);
    }
  }
  SpMatR A(nb * bs, nb * bs);
  A.setFromTriplets(trip.begin(), trip.end());
  A.makeCompressed();
  return A;
}

// κ of A and of the block-Jacobi preconditioned matrix P^{-1/2} A P^{-1/2} (dense eigenvalues).
double condition(const Eigen::MatrixXd& A) {
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A, Eigen::EigenvaluesOnly).eigenvalues();
  return ev.maxCoeff() / ev.minCoeff();
}
double preconditioned_condition(const Eigen::MatrixXd& A, int bs) {
  Eigen::MatrixXd Pih = Eigen::MatrixXd::Zero(A.rows(), A.cols());  // P^{-1/2}, block diagonal
  for (int b = 0; b < A.rows() / bs; ++b) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A.block(b * bs, b * bs, bs, bs));
    Pih.block(b * bs, b * bs, bs, bs) = es.operatorInverseSqrt();
  }
  return condition(Pih * A * Pih);
}
// The classical CG bound: ‖e‖_A falls at least like 2 ((√κ − 1)/(√κ + 1))^k. The solver stops on
// the residual, ‖r‖ ≤ √κ_A ‖e‖_A-relative, so ask for tol/√κ(A) in the energy norm.
int cg_iteration_bound(double kappa_prec, double kappa_A, double tol) {
  const double rate = (std::sqrt(kappa_prec) - 1) / (std::sqrt(kappa_prec) + 1);
  return static_cast<int>(std::ceil(std::log(tol / (2 * std::sqrt(kappa_A))) / std::log(rate)));
}

Eigen::VectorXd random_vector(long n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> N(0, 1);
  Eigen::VectorXd v(n);
  for (long i = 0; i < n; ++i) v[i] = N(rng);
  return v;
}

}  // namespace

TEST(BlockPcg, MatchesADirectSolveWithinTheConditionBound) {
  for (int bs : {1, 2, 3}) {
    const SpMatR A = random_block_spd(150, bs, 1e2, 1e3, 11 + bs);
    const Eigen::MatrixXd Ad(A);
    const Eigen::VectorXd b = random_vector(A.rows(), 5);
    const Eigen::VectorXd x_direct = Ad.llt().solve(b);
    Eigen::VectorXd x(A.rows());
    BlockPcg pcg(bs);
    double relres = -1;
    const double tol = 1e-10;
    const int it = pcg.solve(A, b.data(), x.data(), tol, 5000, &relres);
    EXPECT_GT(it, 0);
    EXPECT_LE(relres, tol);  // the stopping test, on the recursive residual
    // The true residual differs from the recursive one by round-off accumulated over the
    // iterations, O(it · ε · ‖A‖ ‖x‖) relative to ‖b‖ ≈ 1e-12 here: 10 tol is a wide margin.
    const double true_relres = (b - Ad * x).norm() / b.norm();
    EXPECT_LE(true_relres, 10 * tol) << "bs " << bs;
    // ‖x − x*‖/‖x*‖ ≤ κ(A) · ‖r‖/‖b‖ (and the direct solve is exact to ~κ ε).
    const double kappa = condition(Ad);
    EXPECT_LE((x - x_direct).norm() / x_direct.norm(), kappa * 10 * tol + 1e-12) << "bs " << bs << " kappa " << kappa;
  }
}

TEST(BlockPcg, IterationsStayWithinTheConjugateGradientBound) {
  for (int bs : {1, 2, 3}) {
    const SpMatR A = random_block_spd(150, bs, 1e2, 1e3, 21 + bs);
    const Eigen::MatrixXd Ad(A);
    const Eigen::VectorXd b = random_vector(A.rows(), 6);
    Eigen::VectorXd x(A.rows());
    BlockPcg pcg(bs);
    const double tol = 1e-8;
    const int it = pcg.solve(A, b.data(), x.data(), tol, 5000);
    const int bound = cg_iteration_bound(preconditioned_condition(Ad, bs), condition(Ad), tol);
    // exact-arithmetic bound; round-off delays CG by a few iterations at most at these κ
    EXPECT_LE(it, bound + 5) << "bs " << bs;
    std::printf("bs %d: %d iterations, bound %d\n", bs, it, bound);
  }
}

TEST(BlockPcg, BlockJacobiRemovesIllConditionedBlocks) {
  // Diagonal blocks with eigenvalues 1e4 apart in random directions: the block preconditioner
  // inverts them exactly, the point-Jacobi one (block size 1) only scales their diagonal.
  const int nb = 200;
  const SpMatR A = random_block_spd(nb, 2, 1e4, 10.0, 31);
  const Eigen::MatrixXd Ad(A);
  const Eigen::VectorXd b = random_vector(A.rows(), 7);
  Eigen::VectorXd x2(A.rows()), x1(A.rows());
  BlockPcg block(2), point(1);
  const int it2 = block.solve(A, b.data(), x2.data(), 1e-8, 5000);
  const int it1 = point.solve(A, b.data(), x1.data(), 1e-8, 5000);
  const double k2 = preconditioned_condition(Ad, 2), k1 = preconditioned_condition(Ad, 1);
  EXPECT_LT(k2, k1 / 10);     // the claim behind the test: the blocks carry the ill-conditioning
  EXPECT_LT(2 * it2, it1);    // CG iterations go like √κ: a 10× smaller κ saves > 2×
  std::printf("block 2: %d iterations (kappa %.3g); point Jacobi: %d (kappa %.3g)\n", it2, k2, it1, k1);
  // A block-diagonal matrix is its own preconditioner: one iteration, exact to round-off.
  const SpMatR D = random_block_spd(nb, 3, 1e4, 1e3, 32, true);
  Eigen::VectorXd y(D.rows());
  const Eigen::VectorXd c = random_vector(D.rows(), 8);
  BlockPcg exact(3);
  double relres = -1;
  // P = D^{-1} up to the round-off of inverting 3×3 blocks whose eigenvalues are 1e4 apart
  // (~1e4 ε ≈ 2e-12 relative), so one step reaches any tolerance above that: ask 1e-9.
  EXPECT_EQ(exact.solve(D, c.data(), y.data(), 1e-9, 10, &relres), 1);
  EXPECT_LE(relres, 1e-9);
}

TEST(BlockPcg, SeveralRightHandSidesAndWarmStarts) {
  const SpMatR A = random_block_spd(120, 1, 30, 1e2, 41);
  const Eigen::MatrixXd Ad(A);
  const long n = A.rows();
  Eigen::MatrixXd B(n, 3);  // row-major interleaving below: x[i·3 + c]
  for (int c = 0; c < 3; ++c) B.col(c) = random_vector(n, 50 + c) * std::pow(10.0, c);  // unequal norms
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> Bi = B, X(n, 3);
  BlockPcg pcg(1, 3);
  double relres = -1;
  const int it = pcg.solve(A, Bi.data(), X.data(), 1e-10, 5000, &relres);
  EXPECT_GT(it, 0);
  const Eigen::MatrixXd R = B - Ad * Eigen::MatrixXd(X);
  // joint Frobenius criterion, true residual: round-off margin as in the single-column test
  EXPECT_LE(R.norm() / B.norm(), 10 * 1e-10);
  // Warm start from the solution: nothing left to do.
  EXPECT_EQ(pcg.solve(A, Bi.data(), X.data(), 1e-10, 5000, &relres, true), 0);
  // Warm start from a guess off by 1e-4: the error to remove is 1e-4 of the cold one, so the
  // iteration needs fewer steps (CG's error bound falls geometrically).
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> G = X;
  for (long i = 0; i < n; ++i) G.row(i) *= 1 + 1e-4 * std::sin(double(i));
  const int warm = pcg.solve(A, Bi.data(), G.data(), 1e-10, 5000, &relres, true);
  EXPECT_LT(warm, it);
  EXPECT_LE(relres, 1e-10);
  // A zero right-hand side: x = 0 without iterating.
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> Z = Eigen::MatrixXd::Zero(n, 3), Y = X;
  EXPECT_EQ(pcg.solve(A, Z.data(), Y.data(), 1e-10, 5000, &relres), 0);
  EXPECT_EQ(Y.cwiseAbs().maxCoeff(), 0.0);
}

TEST(BlockPcg, StopsWithoutMovingOnNegativeCurvature) {
  // A = [[1, 3], [3, 1]] (eigenvalues 4, −2), b = (1, −1) lies along the negative eigenvector:
  // pᵀAp < 0 at the first step. The solver returns x = 0 with relres = 1, which the rotation
  // solve reads as a stalled CG (gsmb_wall.cpp, kStalledCg = 0.5).
  Eigen::MatrixXd Ad(2, 2);
  Ad << 1, 3, 3, 1;
  const SpMatR A = Ad.sparseView();
  const double b[2] = {1, -1};
  double x[2] = {7, 7}, relres = -1;
  BlockPcg pcg(1);
  EXPECT_EQ(pcg.solve(A, b, x, 1e-10, 100, &relres), 0);
  EXPECT_EQ(x[0], 0.0);
  EXPECT_EQ(x[1], 0.0);
  EXPECT_EQ(relres, 1.0);
}

TEST(BlockPcg, BitIdenticalForAnyThreadCount) {
  // Above the size at which the solve runs on a team (parallel_thresholds.hpp), the chunked sums
  // fix the arithmetic: 1, 2 and 3 threads give the same bits, for the block sizes and column
  // counts capsflow uses (2×2 blocks, one column: rotations; Jacobi, three columns: the load)
  // and a 3×3 case; from zero and from a guess.
  struct Case { int nb, bs, k; };
  const int nt = omp_get_max_threads();
  for (const Case cs : {Case{3000, 3, 1}, Case{2562, 2, 1}, Case{2562, 1, 3}}) {
    const SpMatR A = random_block_spd(cs.nb, cs.bs, 1e2, 1e2, 61);
    const Eigen::VectorXd b = random_vector(A.rows() * cs.k, 9);
    for (const bool guess : {false, true}) {
      std::vector<Eigen::VectorXd> xs;
      std::vector<int> its;
      for (const int threads : {1, 2, 3}) {
        Eigen::VectorXd x = Eigen::VectorXd::Constant(A.rows() * cs.k, 0.25);
        BlockPcg pcg(cs.bs, cs.k);
        omp_set_num_threads(threads);
        its.push_back(pcg.solve(A, b.data(), x.data(), 1e-10, 5000, nullptr, guess));
        xs.push_back(x);
      }
      omp_set_num_threads(nt);
      for (int t = 1; t < 3; ++t) {
        EXPECT_EQ(its[0], its[t]) << "bs " << cs.bs << " columns " << cs.k;
        // the property under test: bit-equality, so the tolerance is 0
        EXPECT_EQ((xs[0] - xs[t]).cwiseAbs().maxCoeff(), 0.0) << "bs " << cs.bs << " columns " << cs.k;
      }
    }
  }
}
