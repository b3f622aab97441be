#include "capsflow/shell/pcg.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>

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

namespace {

// The PCG of BlockPcg::solve for a block size BS and K columns known at compile time, so that the
// per-row sums of a matrix pass stay in registers (with K a run-time value they went through
// memory: a store-to-load dependency on every non-zero, ~80 % of the solve's time).
template <int BS, int K>
int pcg_solve(const SpMatR& A, const double* pinv, const double* b, double* x, double tol, int max_iter,
              double* relres, bool x_is_guess, double* r, double* z, double* p, double* q, double* part) {
  // Three fused passes per iteration (q = A p with p.q; x/r update with z = P r, r.z, r.r;
  // p = z + beta p), each over fixed chunks of block rows with per-chunk partial sums added
  // serially: deterministic for any thread count, and few synchronisation points.
  const long n = A.rows();
  const long nb = n / BS;
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* val = A.valuePtr();
  constexpr long C = 1024;  // block rows per chunk: fixes the summation order (changing it changes the last bits)
  constexpr int kSlots = 3 * kMaxColumns;  // partial sums per chunk
  const long nc = (nb + C - 1) / C;
  const bool par = n * K > kParallelPcgEntries;
  auto sum = [&](int slot) {
    double s = 0;
    for (long c = 0; c < nc; ++c) s += part[kSlots * c + slot];
    return s;
  };
  // z = P r on one block of rows, every column.
  auto precond_block = [&](long blk) {
    const double* P = &pinv[blk * BS * BS];
    for (int i = 0; i < BS; ++i)
      for (int c = 0; c < K; ++c) {
        double s = 0;
        for (int j = 0; j < BS; ++j) s += P[i * BS + j] * r[(blk * BS + j) * K + c];
        z[(blk * BS + i) * K + c] = s;
      }
  };
  // Row `row` of A times the n × K vector v, into out[0..K) (summed in registers, in pattern order).
  auto row_times = [&](long row, const double* v, double* out) {
    double s[K];
    for (int c = 0; c < K; ++c) s[c] = 0;
    for (int k = outer[row]; k < outer[row + 1]; ++k) {
      const double m = val[k];
      const double* vk = v + static_cast<long>(inner[k]) * K;
      for (int c = 0; c < K; ++c) s[c] += m * vk[c];
    }
    for (int c = 0; c < K; ++c) out[c] = s[c];
  };
  // r = b − A x0 (x0 = 0 unless x_is_guess), z = P r, p = z; partials b.b, r.z per column, r.r
#pragma omp parallel for schedule(static) if (par)
  for (long ch = 0; ch < nc; ++ch) {
    double bb = 0, rr = 0, rz[K];
    for (int c = 0; c < K; ++c) rz[c] = 0;
    const long e = std::min(nb, (ch + 1) * C);
    for (long blk = ch * C; blk < e; ++blk) {
      for (int i = 0; i < BS; ++i) {
        const long row = blk * BS + i;
        double ax[K];
        for (int c = 0; c < K; ++c) ax[c] = 0;
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
      for (int i = 0; i < BS; ++i)
        for (int c = 0; c < K; ++c) {
          const long k = (blk * BS + i) * K + c;
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
  double rz[K];
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
      double pq[K];
      for (int c = 0; c < K; ++c) pq[c] = 0;
      const long e = std::min(n, (ch + 1) * C * BS);
      for (long row = ch * C * BS; row < e; ++row) {
        row_times(row, p, q + row * K);
        for (int c = 0; c < K; ++c) pq[c] += p[row * K + c] * q[row * K + c];
      }
      for (int c = 0; c < K; ++c) part[kSlots * ch + c] = pq[c];
    }
    // A column whose matrix is not positive along p (or that has converged exactly) stops moving.
    double alpha[K];
    bool any = false;
    for (int c = 0; c < K; ++c) {
      const double pq = sum(c);
      alpha[c] = pq > 0 ? rz[c] / pq : 0.0;
      any = any || pq > 0;
    }
    if (!any) break;  // not positive definite along p: return the current iterate
#pragma omp parallel for schedule(static) if (par)
    for (long ch = 0; ch < nc; ++ch) {
      double rr = 0, rzp[K];
      for (int c = 0; c < K; ++c) rzp[c] = 0;
      const long e = std::min(nb, (ch + 1) * C);
      for (long blk = ch * C; blk < e; ++blk) {
        for (int i = 0; i < BS; ++i)
          for (int c = 0; c < K; ++c) {
            const long k = (blk * BS + i) * K + c;
            x[k] += alpha[c] * p[k];
            r[k] -= alpha[c] * q[k];
            rr += r[k] * r[k];
          }
        precond_block(blk);
        for (int i = 0; i < BS; ++i)
          for (int c = 0; c < K; ++c) {
            const long k = (blk * BS + i) * K + c;
            rzp[c] += r[k] * z[k];
          }
      }
      part[kSlots * ch] = rr;
      for (int c = 0; c < K; ++c) part[kSlots * ch + 1 + c] = rzp[c];
    }
    ++it;
    rn = std::sqrt(sum(0));
    if (rn <= tol * bnorm) break;
    double beta[K];
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

}  // namespace

int BlockPcg::solve(const SpMatR& A, const double* b, double* x, double tol, int max_iter, double* relres,
                    bool x_is_guess) {
  const long n = A.rows();
  r_.resize(n * k_); z_.resize(n * k_); p_.resize(n * k_); q_.resize(n * k_);
  setup_preconditioner(A);
  const long nc = (n / bs_ + 1023) / 1024;
  if (static_cast<long>(partial_.size()) < 3 * kMaxColumns * nc) partial_.resize(3 * kMaxColumns * nc);
  auto run = [&](auto bs, auto k) {
    return pcg_solve<decltype(bs)::value, decltype(k)::value>(A, pinv_.data(), b, x, tol, max_iter, relres, x_is_guess,
                                                              r_.data(), z_.data(), p_.data(), q_.data(), partial_.data());
  };
  using I1 = std::integral_constant<int, 1>;
  using I2 = std::integral_constant<int, 2>;
  using I3 = std::integral_constant<int, 3>;
  auto with_k = [&](auto bs) {
    switch (k_) {
      case 1: return run(bs, I1{});
      case 2: return run(bs, I2{});
      default: return run(bs, I3{});
    }
  };
  switch (bs_) {
    case 1: return with_k(I1{});
    case 2: return with_k(I2{});
    default: return with_k(I3{});
  }
}

}  // namespace capsflow::shell
