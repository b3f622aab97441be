#include "capsflow/shell/load_recovery.hpp"

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
  assemble(x);
  const long n = topo_.n_nodes;
  if (q.rows() != n) q.resize(n, 3);
  r_.resize(3 * n); z_.resize(3 * n); p_.resize(3 * n); Ap_.resize(3 * n);
  const int* outer = M_.outerIndexPtr();
  const int* inner = M_.innerIndexPtr();
  const double* val = M_.valuePtr();
  // 3 interleaved CGs sharing one matrix pass; x = q (row-major N x 3), r/z/p same layout.
  double* X = q.data();
  const double* B = R.data();
  double* r = r_.data(); double* z = z_.data(); double* p = p_.data(); double* Ap = Ap_.data();
  auto matvec = [&](const double* in, double* out) {
#pragma omp parallel for schedule(static) if (n > 2048)
    for (long i = 0; i < n; ++i) {
      double s0 = 0, s1 = 0, s2 = 0;
      for (int k = outer[i]; k < outer[i + 1]; ++k) {
        const double m = val[k];
        const double* u = in + 3L * inner[k];
        s0 += m * u[0]; s1 += m * u[1]; s2 += m * u[2];
      }
      out[3 * i] = s0; out[3 * i + 1] = s1; out[3 * i + 2] = s2;
    }
  };
  auto dot3 = [&](const double* a, const double* b, double out[3]) {
    for (int c = 0; c < 3; ++c)
      out[c] = par::det_sum(n, partial_, [&](long i) { return a[3 * i + c] * b[3 * i + c]; });
  };
  // initial guess: lumped
#pragma omp parallel for schedule(static) if (n > 4096)
  for (long i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) X[3 * i + c] = B[3 * i + c] / lumped_[i];
  matvec(X, Ap);
#pragma omp parallel for schedule(static) if (n > 4096)
  for (long i = 0; i < 3 * n; ++i) r[i] = B[i] - Ap[i];
  double bb[3];
  dot3(B, B, bb);
  const double bnorm = std::sqrt(bb[0] + bb[1] + bb[2]);
  relres_ = 0;
  if (bnorm == 0) return 0;
  // Jacobi
  auto precond = [&](const double* in, double* out) {
#pragma omp parallel for schedule(static) if (n > 4096)
    for (long i = 0; i < n; ++i) {
      const double inv = 1.0 / val[outer[i] + topo_.diag_pos[i]];
      for (int c = 0; c < 3; ++c) out[3 * i + c] = in[3 * i + c] * inv;
    }
  };
  precond(r, z);
#pragma omp parallel for schedule(static) if (n > 4096)
  for (long i = 0; i < 3 * n; ++i) p[i] = z[i];
  double rz[3], rr[3];
  dot3(r, z, rz);
  dot3(r, r, rr);
  int it = 0;
  double rn = std::sqrt(rr[0] + rr[1] + rr[2]);
  while (rn > tol * bnorm && it < 500) {
    matvec(p, Ap);
    double pAp[3], alpha[3];
    dot3(p, Ap, pAp);
    for (int c = 0; c < 3; ++c) alpha[c] = pAp[c] > 0 ? rz[c] / pAp[c] : 0.0;
#pragma omp parallel for schedule(static) if (n > 4096)
    for (long i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        X[3 * i + c] += alpha[c] * p[3 * i + c];
        r[3 * i + c] -= alpha[c] * Ap[3 * i + c];
      }
    ++it;
    dot3(r, r, rr);
    rn = std::sqrt(rr[0] + rr[1] + rr[2]);
    if (rn <= tol * bnorm) break;
    precond(r, z);
    double rzn[3], beta[3];
    dot3(r, z, rzn);
    for (int c = 0; c < 3; ++c) {
      beta[c] = rz[c] > 0 ? rzn[c] / rz[c] : 0.0;
      rz[c] = rzn[c];
    }
#pragma omp parallel for schedule(static) if (n > 4096)
    for (long i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) p[3 * i + c] = z[3 * i + c] + beta[c] * p[3 * i + c];
  }
  relres_ = rn / bnorm;
  return it;
}

}  // namespace capsflow::shell
