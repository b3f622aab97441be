#pragma once
// The one preconditioned conjugate gradient of capsflow: on an Eigen row-major sparse matrix,
// for one right-hand side (the rotation tangent) or several interleaved ones sharing each matrix
// pass (the mass matrix, one per Cartesian component). Work vectors are allocated once and
// reused (no allocation per call once sized). OpenMP-parallel SpMV (row loop) and deterministic
// chunked dot products, so results do not depend on the thread count.
#include <Eigen/SparseCore>
#include <vector>

namespace capsflow::shell {

using SpMatR = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

/// y = A x (parallel over rows, deterministic).
void spmv(const SpMatR& A, const double* x, double* y);

/// PCG with a block-Jacobi preconditioner of block size bs (1, 2 or 3; the diagonal blocks are
/// read from the matrix, whose pattern must contain them) on `columns` (1 to 3) right-hand
/// sides at once: b and x are n × columns, row-major (x[i·columns + c]). Each column is its own
/// CG (own step lengths); they share every pass over the matrix. Stops when the joint residual
/// ||B − A X||_F <= tol ||B||_F, or after max_iter iterations.
class BlockPcg {
 public:
  explicit BlockPcg(int block_size = 2, int columns = 1);
  /// Solves A X = B from X = 0, or from the incoming X when `x_is_guess`. Returns the number of
  /// iterations; *relres = ||B − A X||_F / ||B||_F (recursive residual).
  int solve(const SpMatR& A, const double* b, double* x, double tol, int max_iter, double* relres = nullptr,
            bool x_is_guess = false);

 private:
  void setup_preconditioner(const SpMatR& A);
  int bs_, k_;
  std::vector<double> r_, z_, p_, q_, pinv_, partial_;
};

}  // namespace capsflow::shell
