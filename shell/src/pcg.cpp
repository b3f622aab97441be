#include "capsflow/shell/pcg.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "capsflow/shell/parallel.hpp"
#include "capsflow/shell/parallel_thresholds.hpp"

namespace capsflow::shell {

namespace {
constexpr int kMaxColumns = 3;
}  // namespace

void spmv(const SpMatR& A, const double* x, double* y) {
  const int n = static_cast<int>(A.rows());
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* val = A.valuePtr();
#pragma omp parallel for schedule(static) if (n > kParallelRows)
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
#pragma omp parallel for schedule(static) if (nb > kParallelRows)
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

BlockPcg::BlockPcg(int block_size, int columns) : bs_(block_size), k_(columns) {
  if (bs_ < 1 || bs_ > 3) throw std::invalid_argument("BlockPcg: block size must be 1, 2 or 3");
  if (k_ < 1 || k_ > kMaxColumns) throw std::invalid_argument("BlockPcg: 1 to 3 right-hand sides");
}

int BlockPcg::solve(const SpMatR& A, const double* b, double* x, double tol, int max_iter, double* relres,
                    bool x_is_guess) {
  // Three fused passes per iteration (q = A p with p.q; x/r update with z = P r, r.z, r.r;
  // p = z + beta p), each over fixed chunks of block rows with per-chunk partial sums added
  // serially: deterministic for any thread count, and few synchronisation points.
  const int K = k_, bs = bs_;
  const long n = A.rows();
  const long nb = n / bs;
  r_.resize(n * K); z_.resize(n * K); p_.resize(n * K); q_.resize(n * K);
  setup_preconditioner(A);
  double* r = r_.data(); double* z = z_.data(); double* p = p_.data(); double* q = q_.data();
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* val = A.valuePtr();
  constexpr long C = 1024;  // block rows per chunk: fixes the summation order (changing it changes the last bits)
  constexpr int kSlots = 3 * kMaxColumns;  // partial sums per chunk
  const long nc = (nb + C - 1) / C;
  if (static_cast<long>(partial_.size()) < kSlots * nc) partial_.resize(kSlots * nc);
  double* part = partial_.data();
  const bool par = n * K > kParallelPcgEntries;
  auto sum = [&](int slot) {
    double s = 0;
    for (long c = 0; c < nc; ++c) s += part[kSlots * c + slot];
    return s;
  };
  // z = P r on one block of rows, every column.
  auto precond_block = [&](long blk) {
    const double* P = &pinv_[blk * bs * bs];
    for (int i = 0; i < bs; ++i)
      for (int c = 0; c < K; ++c) {
        double s = 0;
        for (int j = 0; j < bs; ++j) s += P[i * bs + j] * r[(blk * bs + j) * K + c];
        z[(blk * bs + i) * K + c] = s;
      }
  };
  // Row `row` of A times the n × K vector v, into out[0..K).
  auto row_times = [&](long row, const double* v, double* out) {
    for (int c = 0; c < K; ++c) out[c] = 0;
    for (int k = outer[row]; k < outer[row + 1]; ++k) {
      const double m = val[k];
      const double* vk = v + static_cast<long>(inner[k]) * K;
      for (int c = 0; c < K; ++c) out[c] += m * vk[c];
    }
  };
  // r = b − A x0 (x0 = 0 unless x_is_guess), z = P r, p = z; partials b.b, r.z per column, r.r
#pragma omp parallel for schedule(static) if (par)
  for (long ch = 0; ch < nc; ++ch) {
    double bb = 0, rr = 0, rz[kMaxColumns] = {0, 0, 0};
    const long e = std::min(nb, (ch + 1) * C);
    for (long blk = ch * C; blk < e; ++blk) {
      for (int i = 0; i < bs; ++i) {
        const long row = blk * bs + i;
        double ax[kMaxColumns] = {0, 0, 0};
        if (x_is_guess) row_times(row, x, ax);
        for (int c = 0; c < K; ++c) {
          const long k = row * K + c;
          if (!x_is_guess) x[k] = 0;
          r[k] = b[k] - ax[c];
          bb += b[k] * b[k];
          rr += r[k] * r[k];
        }
      }
      precond_block(blk);
      for (int i = 0; i < bs; ++i)
        for (int c = 0; c < K; ++c) {
          const long k = (blk * bs + i) * K + c;
          p[k] = z[k];
          rz[c] += r[k] * z[k];
        }
    }
    part[kSlots * ch] = bb;
    part[kSlots * ch + 1] = rr;
    for (int c = 0; c < K; ++c) part[kSlots * ch + 2 + c] = rz[c];
  }
  const double bnorm = std::sqrt(sum(0));
  double rn = std::sqrt(sum(1));
  double rz[kMaxColumns];
  for (int c = 0; c < K; ++c) rz[c] = sum(2 + c);
  if (relres) *relres = 0;
  if (bnorm == 0) {
    std::fill(x, x + n * K, 0.0);
    return 0;
  }
  int it = 0;
  while (rn > tol * bnorm && it < max_iter) {
#pragma omp parallel for schedule(static) if (par)
    for (long ch = 0; ch < nc; ++ch) {
      double pq[kMaxColumns] = {0, 0, 0};
      const long e = std::min(n, (ch + 1) * C * bs);
      for (long row = ch * C * bs; row < e; ++row) {
        row_times(row, p, q + row * K);
        for (int c = 0; c < K; ++c) pq[c] += p[row * K + c] * q[row * K + c];
      }
      for (int c = 0; c < K; ++c) part[kSlots * ch + c] = pq[c];
    }
    // A column whose matrix is not positive along p (or that has converged exactly) stops moving.
    double alpha[kMaxColumns];
    bool any = false;
    for (int c = 0; c < K; ++c) {
      const double pq = sum(c);
      alpha[c] = pq > 0 ? rz[c] / pq : 0.0;
      any = any || pq > 0;
    }
    if (!any) break;  // not positive definite along p: return the current iterate
#pragma omp parallel for schedule(static) if (par)
    for (long ch = 0; ch < nc; ++ch) {
      double rr = 0, rzp[kMaxColumns] = {0, 0, 0};
      const long e = std::min(nb, (ch + 1) * C);
      for (long blk = ch * C; blk < e; ++blk) {
        for (int i = 0; i < bs; ++i)
          for (int c = 0; c < K; ++c) {
            const long k = (blk * bs + i) * K + c;
            x[k] += alpha[c] * p[k];
            r[k] -= alpha[c] * q[k];
            rr += r[k] * r[k];
          }
        precond_block(blk);
        for (int i = 0; i < bs; ++i)
          for (int c = 0; c < K; ++c) {
            const long k = (blk * bs + i) * K + c;
            rzp[c] += r[k] * z[k];
          }
      }
      part[kSlots * ch] = rr;
      for (int c = 0; c < K; ++c) part[kSlots * ch + 1 + c] = rzp[c];
    }
    ++it;
    rn = std::sqrt(sum(0));
    if (rn <= tol * bnorm) break;
    double beta[kMaxColumns];
    for (int c = 0; c < K; ++c) {
      const double rz_new = sum(1 + c);
      beta[c] = rz[c] > 0 ? rz_new / rz[c] : 0.0;
      rz[c] = rz_new;
    }
#pragma omp parallel for schedule(static) if (par)
    for (long k = 0; k < n * K; ++k) p[k] = z[k] + beta[k % K] * p[k];
  }
  if (relres) *relres = rn / bnorm;
  return it;
}

}  // namespace capsflow::shell
