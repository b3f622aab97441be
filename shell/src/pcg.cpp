#include "capsflow/shell/pcg.hpp"

#include <Eigen/Dense>
#include <cmath>

#include "capsflow/shell/parallel.hpp"

namespace capsflow::shell {

void spmv(const SpMatR& A, const double* x, double* y) {
  const int n = static_cast<int>(A.rows());
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* val = A.valuePtr();
#pragma omp parallel for schedule(static) if (n > 4096)
  for (int i = 0; i < n; ++i) {
    double s = 0;
    for (int k = outer[i]; k < outer[i + 1]; ++k) s += val[k] * x[inner[k]];
    y[i] = s;
  }
}

void BlockPcg::setup_preconditioner(const SpMatR& A) {
  const int n = static_cast<int>(A.rows());
  const int nb = n / bs_;
  pinv_.resize(static_cast<size_t>(nb) * bs_ * bs_);
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* val = A.valuePtr();
#pragma omp parallel for schedule(static) if (nb > 4096)
  for (int b = 0; b < nb; ++b) {
    Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
    for (int k = 0; k < bs_; ++k) {
      const int row = b * bs_ + k;
      for (int p = outer[row]; p < outer[row + 1]; ++p) {
        const int c = inner[p] - b * bs_;
        if (c >= 0 && c < bs_) D(k, c) = val[p];
      }
    }
    double* P = &pinv_[static_cast<size_t>(b) * bs_ * bs_];
    if (bs_ == 1) {
      P[0] = D(0, 0) != 0 ? 1.0 / D(0, 0) : 1.0;
    } else if (bs_ == 2) {
      const double det = D(0, 0) * D(1, 1) - D(0, 1) * D(1, 0);
      P[0] = D(1, 1) / det; P[1] = -D(0, 1) / det; P[2] = -D(1, 0) / det; P[3] = D(0, 0) / det;
    } else {
      const Eigen::Matrix3d Di = D.inverse();
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) P[i * 3 + j] = Di(i, j);
    }
  }
}

void BlockPcg::apply_preconditioner(const double* r, double* z) const {
  const long n = static_cast<long>(r_.size());
  const long nb = n / bs_;
  const int bs = bs_;
#pragma omp parallel for schedule(static) if (nb > 4096)
  for (long b = 0; b < nb; ++b) {
    const double* P = &pinv_[b * bs * bs];
    for (int i = 0; i < bs; ++i) {
      double s = 0;
      for (int j = 0; j < bs; ++j) s += P[i * bs + j] * r[b * bs + j];
      z[b * bs + i] = s;
    }
  }
}

int BlockPcg::solve(const SpMatR& A, const double* b, double* x, double tol, int max_iter, double* relres) {
  const long n = A.rows();
  r_.resize(n); z_.resize(n); p_.resize(n); q_.resize(n);
  setup_preconditioner(A);
  double* r = r_.data(); double* z = z_.data(); double* p = p_.data(); double* q = q_.data();
#pragma omp parallel for schedule(static) if (n > 8192)
  for (long i = 0; i < n; ++i) { x[i] = 0; r[i] = b[i]; }
  const double bnorm = std::sqrt(par::dot(n, b, b, partial_));
  if (relres) *relres = 0;
  if (bnorm == 0) return 0;
  apply_preconditioner(r, z);
#pragma omp parallel for schedule(static) if (n > 8192)
  for (long i = 0; i < n; ++i) p[i] = z[i];
  double rz = par::dot(n, r, z, partial_);
  int it = 0;
  double rn = bnorm;
  while (it < max_iter) {
    spmv(A, p, q);
    const double pq = par::dot(n, p, q, partial_);
    if (!(pq > 0)) break;  // not positive definite along p: return the current iterate
    const double alpha = rz / pq;
#pragma omp parallel for schedule(static) if (n > 8192)
    for (long i = 0; i < n; ++i) { x[i] += alpha * p[i]; r[i] -= alpha * q[i]; }
    ++it;
    rn = std::sqrt(par::dot(n, r, r, partial_));
    if (rn <= tol * bnorm) break;
    apply_preconditioner(r, z);
    const double rz_new = par::dot(n, r, z, partial_);
    const double beta = rz_new / rz;
    rz = rz_new;
#pragma omp parallel for schedule(static) if (n > 8192)
    for (long i = 0; i < n; ++i) p[i] = z[i] + beta * p[i];
  }
  if (relres) *relres = rn / bnorm;
  return it;
}

}  // namespace capsflow::shell
