#pragma once
// Preconditioned conjugate gradient on an Eigen row-major sparse matrix, with all work vectors
// allocated once and reused (no allocation per call once sized). OpenMP-parallel SpMV (row loop)
// and deterministic chunked dot products, so results do not depend on the thread count.
#include <Eigen/SparseCore>
#include <vector>

namespace capsflow::shell {

using SpMatR = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

/// y = A x (parallel over rows, deterministic).
void spmv(const SpMatR& A, const double* x, double* y);

/// PCG with a block-Jacobi preconditioner of block size bs (1, 2 or 3); the diagonal blocks are
/// read from the matrix (the pattern must contain them). Solves A x = b from x = 0.
class BlockPcg {
 public:
  explicit BlockPcg(int block_size = 2) : bs_(block_size) {}
  /// returns the number of iterations; *relres = ||b - A x|| / ||b|| (recursive residual).
  int solve(const SpMatR& A, const double* b, double* x, double tol, int max_iter, double* relres = nullptr);

 private:
  void setup_preconditioner(const SpMatR& A);
  int bs_;
  std::vector<double> r_, z_, p_, q_, pinv_, partial_;
};

}  // namespace capsflow::shell
