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

int BlockPcg::solve(const SpMatR& A, const double* b, double* x, double tol, int max_iter, double* relres) {
  // Three fused passes per iteration (q = A p with p.q; x/r update with z = P r, r.z, r.r;
  // p = z + beta p), each over fixed chunks of block rows with per-chunk partial sums added
  // serially: deterministic for any thread count, and few synchronisation points.
  const long n = A.rows();
  const int bs = bs_;
  const long nb = n / bs;
  r_.resize(n); z_.resize(n); p_.resize(n); q_.resize(n);
  setup_preconditioner(A);
  double* r = r_.data(); double* z = z_.data(); double* p = p_.data(); double* q = q_.data();
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* val = A.valuePtr();
  constexpr long C = 1024;  // block rows per chunk
  const long nc = (nb + C - 1) / C;
  if (static_cast<long>(partial_.size()) < 3 * nc) partial_.resize(3 * nc);
  double* part = partial_.data();
  const bool par = n > 8192;
  auto sum = [&](int k) {
    double s = 0;
    for (long c = 0; c < nc; ++c) s += part[3 * c + k];
    return s;
  };
  auto precond_block = [&](long blk) {
    const double* P = &pinv_[blk * bs * bs];
    for (int i = 0; i < bs; ++i) {
      double s = 0;
      for (int j = 0; j < bs; ++j) s += P[i * bs + j] * r[blk * bs + j];
      z[blk * bs + i] = s;
    }
  };
  // x = 0, r = b, z = P r, p = z; partials b.b, r.z
#pragma omp parallel for schedule(static) if (par)
  for (long c = 0; c < nc; ++c) {
    double bb = 0, rz = 0;
    const long e = std::min(nb, (c + 1) * C);
    for (long blk = c * C; blk < e; ++blk) {
      for (int i = 0; i < bs; ++i) {
        const long k = blk * bs + i;
        x[k] = 0;
        r[k] = b[k];
        bb += b[k] * b[k];
      }
      precond_block(blk);
      for (int i = 0; i < bs; ++i) {
        const long k = blk * bs + i;
        p[k] = z[k];
        rz += r[k] * z[k];
      }
    }
    part[3 * c] = bb;
    part[3 * c + 1] = rz;
  }
  const double bnorm = std::sqrt(sum(0));
  double rz = sum(1);
  if (relres) *relres = 0;
  if (bnorm == 0) return 0;
  int it = 0;
  double rn = bnorm;
  while (it < max_iter) {
#pragma omp parallel for schedule(static) if (par)
    for (long c = 0; c < nc; ++c) {
      double pq = 0;
      const long e = std::min(n, (c + 1) * C * bs);
      for (long row = c * C * bs; row < e; ++row) {
        double s = 0;
        for (int k = outer[row]; k < outer[row + 1]; ++k) s += val[k] * p[inner[k]];
        q[row] = s;
        pq += p[row] * s;
      }
      part[3 * c] = pq;
    }
    const double pq = sum(0);
    if (!(pq > 0)) break;  // not positive definite along p: return the current iterate
    const double alpha = rz / pq;
#pragma omp parallel for schedule(static) if (par)
    for (long c = 0; c < nc; ++c) {
      double rr = 0, rzp = 0;
      const long e = std::min(nb, (c + 1) * C);
      for (long blk = c * C; blk < e; ++blk) {
        for (int i = 0; i < bs; ++i) {
          const long k = blk * bs + i;
          x[k] += alpha * p[k];
          r[k] -= alpha * q[k];
          rr += r[k] * r[k];
        }
        precond_block(blk);
        for (int i = 0; i < bs; ++i) rzp += r[blk * bs + i] * z[blk * bs + i];
      }
      part[3 * c] = rr;
      part[3 * c + 1] = rzp;
    }
    ++it;
    rn = std::sqrt(sum(0));
    if (rn <= tol * bnorm) break;
    const double rz_new = sum(1);
    const double beta = rz_new / rz;
    rz = rz_new;
#pragma omp parallel for schedule(static) if (par)
    for (long k = 0; k < n; ++k) p[k] = z[k] + beta * p[k];
  }
  if (relres) *relres = rn / bnorm;
  return it;
}

}  // namespace capsflow::shell
