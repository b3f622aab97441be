#include "capsflow/shell/load_recovery.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "capsflow/shell/parallel.hpp"
#include "capsflow/shell/parallel_thresholds.hpp"

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
  assemble(x, nullptr, nullptr);
  return M_;
}

void LoadRecovery::assemble(const Points& x, const Points* R, Points* q) {
  // One team: element areas, one barrier, then per node its row of M, its lumped mass and (when
  // R is given) the lumped guess q_i = R_i / m_i. Each node sums its own elements: the same
  // arithmetic as a serial pass, for any thread count.
  const int ne = topo_.n_elems, n = topo_.n_nodes;
  double* v = M_.valuePtr();
  const int* outer = M_.outerIndexPtr();
  par::TeamBarrier barrier;
#pragma omp parallel if (ne > kParallelAreaElements)
  {
#pragma omp for schedule(static) nowait
    for (int e = 0; e < ne; ++e) {
      const auto& t = topo_.tri[e];
      const Vec3 a = x.row(t[0]), b = x.row(t[1]), c = x.row(t[2]);
      area_[e] = 0.5 * (b - a).cross(c - a).norm();
    }
    barrier.wait(omp_get_num_threads());
#pragma omp for schedule(static)
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
      if (R) q->row(i) = R->row(i) / lump;
    }
  }
}

void LoadRecovery::solve_lumped(const Points& x, const Points& R, Points& q) {
  assemble(x);
  if (q.rows() != R.rows()) q.resize(R.rows(), 3);
  for (int i = 0; i < topo_.n_nodes; ++i) q.row(i) = R.row(i) / lumped_[i];
}

int LoadRecovery::solve(const Points& x, const Points& R, Points& q, double tol) {
  if (&q == &R || &q == &x) throw std::invalid_argument("LoadRecovery::solve: q must not alias R or x");
  if (R.rows() != topo_.n_nodes) throw std::invalid_argument("LoadRecovery: R has the wrong number of rows");
  if (x.rows() != topo_.n_nodes) throw std::invalid_argument("LoadRecovery: x has the wrong number of rows");
  const long n = topo_.n_nodes;
  const bool warm = warm_start_ && q.rows() == n;
  if (q.rows() != n) q.resize(n, 3);
  // Initial guess: the incoming q if warm-started, else the lumped solution (q_i = R_i / m_i),
  // computed in the assembly's team.
  assemble(x, warm ? nullptr : &R, warm ? nullptr : &q);
  // One CG per Cartesian component (Jacobi preconditioner), sharing each pass over M.
  const int it = pcg_.solve(M_, R.data(), q.data(), tol, kMaxIterations, &relres_, true);
  converged_ = relres_ <= tol;
  return it;
}

}  // namespace capsflow::shell
