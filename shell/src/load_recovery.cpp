#include "capsflow/shell/load_recovery.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "capsflow/shell/parallel.hpp"

namespace capsflow::shell {

LoadRecovery::LoadRecovery(const Triangles& tri, Eigen::Index n_nodes) : topo_(tri, n_nodes) {
  const int n = topo_.n_nodes;
  std::vector<Eigen::Triplet<double, int>> trip;
  trip.reserve(topo_.adj.size());
  for (int i = 0; i < n; ++i)
    for (int p = topo_.adj_ptr[i]; p < topo_.adj_ptr[i + 1]; ++p) trip.emplace_back(i, topo_.adj[p], 0.0);
  M_.resize(n, n);
  M_.setFromTriplets(trip.begin(), trip.end());
  M_.makeCompressed();
  area_.resize(topo_.n_elems);
  lumped_.resize(n);
  bbpart_.resize(3 * ((n + 511) / 512));
}

const SpMatR& LoadRecovery::assemble(const Points& x) {
  if (x.rows() != topo_.n_nodes) throw std::invalid_argument("LoadRecovery: x has the wrong number of rows");
  const int ne = topo_.n_elems, n = topo_.n_nodes;
#pragma omp parallel for schedule(static) if (ne > 4096)
  for (int e = 0; e < ne; ++e) {
    const auto& t = topo_.tri[e];
    const Vec3 a = x.row(t[0]), b = x.row(t[1]), c = x.row(t[2]);
    area_[e] = 0.5 * (b - a).cross(c - a).norm();
  }
  double* v = M_.valuePtr();
  const int* outer = M_.outerIndexPtr();
#pragma omp parallel for schedule(static) if (n > 4096)
  for (int i = 0; i < n; ++i) {
    for (int k = outer[i]; k < outer[i + 1]; ++k) v[k] = 0;
    double lump = 0;
    for (int p = topo_.inc_ptr[i]; p < topo_.inc_ptr[i + 1]; ++p) {
      const int e = topo_.inc_elem[p], a = topo_.inc_local[p];
      const double Ae = area_[e];
      lump += Ae / 3.0;
      for (int b = 0; b < 3; ++b) v[outer[i] + topo_.pair_pos[e][a * 3 + b]] += (a == b ? Ae / 6.0 : Ae / 12.0);
    }
    lumped_[i] = lump;
  }
  return M_;
}

void LoadRecovery::solve_lumped(const Points& x, const Points& R, Points& q) {
  assemble(x);
  if (q.rows() != R.rows()) q.resize(R.rows(), 3);
  for (int i = 0; i < topo_.n_nodes; ++i) q.row(i) = R.row(i) / lumped_[i];
}

int LoadRecovery::solve(const Points& x, const Points& R, Points& q, double tol) {
  if (&q == &R || &q == &x) throw std::invalid_argument("LoadRecovery::solve: q must not alias R or x");
  if (R.rows() != topo_.n_nodes) throw std::invalid_argument("LoadRecovery: R has the wrong number of rows");
  assemble(x);
  const long n = topo_.n_nodes;
  const bool warm = warm_start_ && q.rows() == n;
  if (q.rows() != n) q.resize(n, 3);
  r_.resize(3 * n); z_.resize(3 * n); p_.resize(3 * n); Ap_.resize(3 * n);
  const int* outer = M_.outerIndexPtr();
  const int* inner = M_.innerIndexPtr();
  const double* val = M_.valuePtr();
  // 3 interleaved CGs (one per component) sharing each pass over the matrix; all vectors are
  // row-major N x 3. Each pass runs over fixed chunks of rows and stores per-chunk partial sums,
  // added serially afterwards: deterministic for any thread count.
  double* X = q.data();
  const double* B = R.data();
  double* r = r_.data(); double* z = z_.data(); double* p = p_.data(); double* Ap = Ap_.data();
  constexpr long C = 512;
  const long nc = (n + C - 1) / C;
  if (static_cast<long>(partial_.size()) < 6 * nc) partial_.resize(6 * nc);
  double* part = partial_.data();
  auto reduce = [&](int k, double out[]) {
    for (int c = 0; c < k; ++c) out[c] = 0;
    for (long b = 0; b < nc; ++b)
      for (int c = 0; c < k; ++c) out[c] += part[6 * b + c];
  };
  auto row_mv = [&](const double* in, long i, double s[3]) {
    s[0] = s[1] = s[2] = 0;
    for (int k = outer[i]; k < outer[i + 1]; ++k) {
      const double m = val[k];
      const double* u = in + 3L * inner[k];
      s[0] += m * u[0]; s[1] += m * u[1]; s[2] += m * u[2];
    }
  };
  const bool par = n > 2048;
  // r = B - M X0 (X0: the incoming q if warm-started, else the lumped solution); z = D^-1 r; p = z
  if (!warm) {
#pragma omp parallel for schedule(static) if (par)
    for (long i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) X[3 * i + c] = B[3 * i + c] / lumped_[i];
  }
#pragma omp parallel for schedule(static) if (par)
  for (long b = 0; b < nc; ++b) {
    double rz[3] = {0, 0, 0}, rr[3] = {0, 0, 0}, bb[3] = {0, 0, 0};
    const long e = std::min(n, (b + 1) * C);
    for (long i = b * C; i < e; ++i) {
      double s[3];
      row_mv(X, i, s);
      const double inv = 1.0 / val[outer[i] + topo_.diag_pos[i]];
      for (int c = 0; c < 3; ++c) {
        const long k = 3 * i + c;
        r[k] = B[k] - s[c];
        z[k] = r[k] * inv;
        p[k] = z[k];
        rz[c] += r[k] * z[k];
        rr[c] += r[k] * r[k];
        bb[c] += B[k] * B[k];
      }
    }
    for (int c = 0; c < 3; ++c) {
      part[6 * b + c] = rz[c];
      part[6 * b + 3 + c] = rr[c];
    }
    bbpart_[b * 3] = bb[0]; bbpart_[b * 3 + 1] = bb[1]; bbpart_[b * 3 + 2] = bb[2];
  }
  double rz[3], tmp[6];
  reduce(6, tmp);
  for (int c = 0; c < 3; ++c) rz[c] = tmp[c];
  double rn2 = tmp[3] + tmp[4] + tmp[5], bn2 = 0;
  for (long b = 0; b < 3 * nc; ++b) bn2 += bbpart_[b];
  const double bnorm = std::sqrt(bn2);
  relres_ = 0;
  if (bnorm == 0) {
    q.setZero();
    return 0;
  }
  int it = 0;
  while (std::sqrt(rn2) > tol * bnorm && it < 500) {
    // Ap = M p, partial p.Ap
#pragma omp parallel for schedule(static) if (par)
    for (long b = 0; b < nc; ++b) {
      double pap[3] = {0, 0, 0};
      const long e = std::min(n, (b + 1) * C);
      for (long i = b * C; i < e; ++i) {
        double s[3];
        row_mv(p, i, s);
        for (int c = 0; c < 3; ++c) {
          Ap[3 * i + c] = s[c];
          pap[c] += p[3 * i + c] * s[c];
        }
      }
      for (int c = 0; c < 3; ++c) part[6 * b + c] = pap[c];
    }
    double pAp[3], alpha[3];
    reduce(3, pAp);
    for (int c = 0; c < 3; ++c) alpha[c] = pAp[c] > 0 ? rz[c] / pAp[c] : 0.0;
    // x += alpha p, r -= alpha Ap, z = D^-1 r, partials r.z and r.r
#pragma omp parallel for schedule(static) if (par)
    for (long b = 0; b < nc; ++b) {
      double rzp[3] = {0, 0, 0}, rrp[3] = {0, 0, 0};
      const long e = std::min(n, (b + 1) * C);
      for (long i = b * C; i < e; ++i) {
        const double inv = 1.0 / val[outer[i] + topo_.diag_pos[i]];
        for (int c = 0; c < 3; ++c) {
          const long k = 3 * i + c;
          X[k] += alpha[c] * p[k];
          r[k] -= alpha[c] * Ap[k];
          z[k] = r[k] * inv;
          rzp[c] += r[k] * z[k];
          rrp[c] += r[k] * r[k];
        }
      }
      for (int c = 0; c < 3; ++c) {
        part[6 * b + c] = rzp[c];
        part[6 * b + 3 + c] = rrp[c];
      }
    }
    ++it;
    reduce(6, tmp);
    rn2 = tmp[3] + tmp[4] + tmp[5];
    if (std::sqrt(rn2) <= tol * bnorm) break;
    double beta[3];
    for (int c = 0; c < 3; ++c) {
      beta[c] = rz[c] > 0 ? tmp[c] / rz[c] : 0.0;
      rz[c] = tmp[c];
    }
#pragma omp parallel for schedule(static) if (par)
    for (long k = 0; k < 3 * n; ++k) p[k] = z[k] + beta[k % 3] * p[k];
  }
  relres_ = std::sqrt(rn2) / bnorm;
  return it;
}

}  // namespace capsflow::shell
