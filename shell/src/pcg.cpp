#include "capsflow/shell/pcg.hpp"

#include <omp.h>

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

// Block rows per chunk of the PCG's reductions: each chunk's partial sums run in row order, the
// chunks' partials are added in chunk order. Chunks depend on n only, so the sums are the same for
// any thread count; 64 block rows split 2 562 nodes into 41 chunks, balanced on 2–16 threads.
constexpr long kPcgChunk = 64;

// Where one thread's partial sums of a reduction go: slots per chunk.
constexpr int kSlots = 1 + kMaxColumns;

// The PCG of BlockPcg::solve for a block size BS and K columns known at compile time (a row's
// sums of a matrix pass stay in registers), in ONE parallel region for the whole solve: the team
// is started once per solve. Every thread owns a contiguous range of chunks; after a barrier every
// thread adds all chunks' partials itself, in chunk order, so all threads take the same decisions
// (no broadcast).
//
// Per iteration: p = z + β p_old on own rows, a barrier (the product reads neighbours' p); pass A
// — q = A p, partial p·q —, a barrier; pass B — x += α p, r −= α q, z = P r, partials r·r and
// r·z —, a barrier. Three barriers, not two: computing the neighbours' p inside the product
// instead (z_j + β p_old,j per matrix entry) doubles the vectors it reads, and on 2 threads made
// the solve at 40 962 nodes slower than on one (perf/RESULTS.md §1.3). Every multiply-add is fused
// explicitly (par::fmadd): the same bits for any thread count.
template <int BS, int K>
int pcg_solve(const SpMatR& A, const double* pinv, const double* b, double* x, double tol, int max_iter,
              double* relres, bool x_is_guess, double* r, double* z, double* p_a, double* p_b, double* q, double* part) {
  using par::fmadd;
  const long n = A.rows();
  const long nb = n / BS;
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* val = A.valuePtr();
  const long nc = (nb + kPcgChunk - 1) / kPcgChunk;
  double* part_init = part;                   // b·b, r·r, r·z per column: 2 + K slots per chunk
  double* part_a = part + (2 + K) * nc;       // p·q per column
  double* part_b = part_a + kSlots * nc;      // r·r, r·z per column
  auto sum = [&](const double* pp, int stride, int slot) {
    double s = 0;
    for (long c = 0; c < nc; ++c) s += pp[stride * c + slot];
    return s;
  };
  // z = P r on one block of rows, every column.
  auto precond_block = [&](long blk) {
    const double* P = &pinv[blk * BS * BS];
    for (int i = 0; i < BS; ++i)
      for (int c = 0; c < K; ++c) {
        double s = 0;
        for (int j = 0; j < BS; ++j) s = fmadd(P[i * BS + j], r[(blk * BS + j) * K + c], s);
        z[(blk * BS + i) * K + c] = s;
      }
  };
  // Row `row` of A times the vector whose row j is vec(j, c), into out[0..K), in pattern order.
  auto row_times = [&](long row, double* out, auto&& vec) {
    double s[K];
    for (int c = 0; c < K; ++c) s[c] = 0;
    for (int k = outer[row]; k < outer[row + 1]; ++k) {
      const double m = val[k];
      const long j = inner[k];
      for (int c = 0; c < K; ++c) s[c] = fmadd(m, vec(j, c), s[c]);
    }
    for (int c = 0; c < K; ++c) out[c] = s[c];
  };
  const bool team = n * K > kParallelPcgEntries;
  par::TeamBarrier barrier;
  int iterations = 0;
  double final_rn = 0, bnorm_out = 0;
#pragma omp parallel if (team)
  {
    const int T = omp_get_num_threads(), tid = omp_get_thread_num();
    long ch0, ch1;
    par::thread_range(nc, tid, T, ch0, ch1);
    const long blk0 = ch0 * kPcgChunk, blk1 = std::min(nb, ch1 * kPcgChunk);
    // r = b − A x0 (x0 = 0 unless x_is_guess), z = P r, p = z; partials b.b, r.r, r.z per column
    for (long ch = ch0; ch < ch1; ++ch) {
      double bb = 0, rr = 0, rz[K];
      for (int c = 0; c < K; ++c) rz[c] = 0;
      const long e = std::min(nb, (ch + 1) * kPcgChunk);
      for (long blk = ch * kPcgChunk; blk < e; ++blk) {
        for (int i = 0; i < BS; ++i) {
          const long row = blk * BS + i;
          double ax[K];
          for (int c = 0; c < K; ++c) ax[c] = 0;
          if (x_is_guess) row_times(row, ax, [&](long j, int c) { return x[j * K + c]; });
          for (int c = 0; c < K; ++c) {
            const long k = row * K + c;
            if (!x_is_guess) x[k] = 0;
            r[k] = b[k] - ax[c];
            bb = fmadd(b[k], b[k], bb);
            rr = fmadd(r[k], r[k], rr);
          }
        }
        precond_block(blk);
        for (int i = 0; i < BS; ++i)
          for (int c = 0; c < K; ++c) {
            const long k = (blk * BS + i) * K + c;
            p_a[k] = z[k];
            rz[c] = fmadd(r[k], z[k], rz[c]);
          }
      }
      double* pp = part_init + (2 + K) * ch;
      pp[0] = bb;
      pp[1] = rr;
      for (int c = 0; c < K; ++c) pp[2 + c] = rz[c];
    }
    barrier.wait(T);
    const double bnorm = std::sqrt(sum(part_init, 2 + K, 0));
    double rn = std::sqrt(sum(part_init, 2 + K, 1));
    double rz[K], beta[K];
    for (int c = 0; c < K; ++c) rz[c] = sum(part_init, 2 + K, 2 + c);
    int it = 0;
    double* p_old = p_b;  // p of the previous iteration
    double* p = p_a;      // p of this iteration (p_a = z already)
    if (bnorm == 0) {
      for (long k = blk0 * BS * K; k < blk1 * BS * K; ++k) x[k] = 0;
    } else {
      while (rn > tol * bnorm && it < max_iter) {
        // p = z + β p_old (the first p is z), then pass A: q = A p, partials p.q
        if (it > 0) {
          for (long k = blk0 * BS * K; k < blk1 * BS * K; ++k) p[k] = fmadd(beta[k % K], p_old[k], z[k]);
          barrier.wait(T);
        }
        for (long ch = ch0; ch < ch1; ++ch) {
          double pq[K];
          for (int c = 0; c < K; ++c) pq[c] = 0;
          const long e = std::min(nb, (ch + 1) * kPcgChunk) * BS;
          for (long row = ch * kPcgChunk * BS; row < e; ++row) {
            double* qr = q + row * K;
            row_times(row, qr, [&](long j, int c) { return p[j * K + c]; });
            for (int c = 0; c < K; ++c) pq[c] = fmadd(p[row * K + c], qr[c], pq[c]);
          }
          for (int c = 0; c < K; ++c) part_a[kSlots * ch + c] = pq[c];
        }
        barrier.wait(T);
        // A column whose matrix is not positive along p (or that has converged exactly) stops moving.
        double alpha[K];
        bool any = false;
        for (int c = 0; c < K; ++c) {
          const double pq = sum(part_a, kSlots, c);
          alpha[c] = pq > 0 ? rz[c] / pq : 0.0;
          any = any || pq > 0;
        }
        if (!any) break;  // not positive definite along p: return the current iterate
        // pass B: x, r, z = P r; partials r.r, r.z
        for (long ch = ch0; ch < ch1; ++ch) {
          double rr = 0, rzp[K];
          for (int c = 0; c < K; ++c) rzp[c] = 0;
          const long e = std::min(nb, (ch + 1) * kPcgChunk);
          for (long blk = ch * kPcgChunk; blk < e; ++blk) {
            for (int i = 0; i < BS; ++i)
              for (int c = 0; c < K; ++c) {
                const long k = (blk * BS + i) * K + c;
                x[k] = fmadd(alpha[c], p[k], x[k]);
                r[k] = fmadd(-alpha[c], q[k], r[k]);
                rr = fmadd(r[k], r[k], rr);
              }
            precond_block(blk);
            for (int i = 0; i < BS; ++i)
              for (int c = 0; c < K; ++c) {
                const long k = (blk * BS + i) * K + c;
                rzp[c] = fmadd(r[k], z[k], rzp[c]);
              }
          }
          part_b[kSlots * ch] = rr;
          for (int c = 0; c < K; ++c) part_b[kSlots * ch + 1 + c] = rzp[c];
        }
        barrier.wait(T);
        ++it;
        rn = std::sqrt(sum(part_b, kSlots, 0));
        if (rn <= tol * bnorm) break;
        for (int c = 0; c < K; ++c) {
          const double rz_new = sum(part_b, kSlots, 1 + c);
          beta[c] = rz[c] > 0 ? rz_new / rz[c] : 0.0;
          rz[c] = rz_new;
        }
        std::swap(p, p_old);
      }
    }
    if (tid == 0) {
      iterations = it;
      final_rn = rn;
      bnorm_out = bnorm;
    }
  }
  if (relres) *relres = bnorm_out == 0 ? 0 : final_rn / bnorm_out;
  return iterations;
}

}  // namespace

int BlockPcg::solve(const SpMatR& A, const double* b, double* x, double tol, int max_iter, double* relres,
                    bool x_is_guess) {
  const long n = A.rows();
  r_.resize(n * k_); z_.resize(n * k_); p_.resize(2 * n * k_); q_.resize(n * k_);
  setup_preconditioner(A);
  const long nc = (n / bs_ + kPcgChunk - 1) / kPcgChunk;
  const long slots = (2 + kMaxColumns + 2 * kSlots) * nc;  // initial, pass-A and pass-B partials
  if (static_cast<long>(partial_.size()) < slots) partial_.resize(slots);
  auto run = [&](auto bs, auto k) {
    return pcg_solve<decltype(bs)::value, decltype(k)::value>(A, pinv_.data(), b, x, tol, max_iter, relres, x_is_guess,
                                                              r_.data(), z_.data(), p_.data(), p_.data() + n * k_, q_.data(),
                                                              partial_.data());
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
