#include "capsflow/shell/wall.hpp"

#include <omp.h>

#include "capsflow/shell/parallel.hpp"
#include "capsflow/shell/parallel_thresholds.hpp"

#include <stdexcept>

namespace capsflow::shell {

MembraneWall::MembraneWall(const Points& X, const Triangles& tri, MembraneLaw law)
    : law_(law), topo_(tri, X.rows()) {
  ref_.resize(topo_.n_elems);
  for (int e = 0; e < topo_.n_elems; ++e) {
    const auto& t = topo_.tri[e];
    const Vec3 Xe[3] = {X.row(t[0]), X.row(t[1]), X.row(t[2])};
    ref_[e] = make_membrane_ref(Xe, t);
  }
}

void MembraneWall::forces(const Points& x, Points& R, WallStats* stats) {
  if (x.rows() != topo_.n_nodes) throw std::invalid_argument("MembraneWall: x has the wrong number of rows");
  if (&R == &x) throw std::invalid_argument("MembraneWall::forces: R_s must not alias x");
  if (R.rows() != x.rows()) R.resize(x.rows(), 3);
  // One team, one barrier: each element's nodal forces to its own record, then each node sums
  // its elements' records in colour order (Topology::inc_elem_by_colour) — the order of the
  // former colour-by-colour pass, so the same bits for any thread count.
  const int ne = topo_.n_elems, n = topo_.n_nodes;
  fe_.resize(ne);
  par::TeamBarrier barrier;
#pragma omp parallel if (ne > kParallelMembranePass)
  {
#pragma omp for schedule(static) nowait
    for (int e = 0; e < ne; ++e) {
      const MembraneRef& m = ref_[e];
      const Vec3 xe[3] = {x.row(m.n[0]), x.row(m.n[1]), x.row(m.n[2])};
      membrane_element(m, law_, xe, fe_[e].f, false);
    }
    barrier.wait(omp_get_num_threads());
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) {
      Vec3 s = Vec3::Zero();
      for (int p = topo_.inc_ptr[i]; p < topo_.inc_ptr[i + 1]; ++p)
        s += fe_[topo_.inc_elem_by_colour[p]].f[topo_.inc_local_by_colour[p]];
      R.row(i) = s.transpose();
    }
  }
  if (stats) *stats = WallStats{};
}

WallEnergies MembraneWall::energies(const Points& x) const {
  WallEnergies E;
  E.membrane = par::det_sum(topo_.n_elems, partial_, [&](long e) {
    const MembraneRef& m = ref_[e];
    const Vec3 xe[3] = {x.row(m.n[0]), x.row(m.n[1]), x.row(m.n[2])};
    Vec3 f[3];
    return membrane_element(m, law_, xe, f);
  });
  return E;
}

void nodal_average(const Topology& topo, const std::vector<double>& v, const std::vector<double>& A,
                   Eigen::VectorXd& out) {
  out.resize(topo.n_nodes);
#pragma omp parallel for schedule(static)
  for (int i = 0; i < topo.n_nodes; ++i) {
    double s = 0, a = 0;
    for (int p = topo.inc_ptr[i]; p < topo.inc_ptr[i + 1]; ++p) {
      s += v[topo.inc_elem[p]];
      a += A[topo.inc_elem[p]];
    }
    out[i] = a > 0 ? s / a : 0.0;
  }
}

void MembraneWall::nodal_energy_maps(const Points& x, Eigen::VectorXd& Em, Eigen::VectorXd& Eb,
                                     Eigen::VectorXd& Esh) const {
  std::vector<double> w(topo_.n_elems), A(topo_.n_elems);
#pragma omp parallel for schedule(static)
  for (int e = 0; e < topo_.n_elems; ++e) {
    const MembraneRef& m = ref_[e];
    const Vec3 xe[3] = {x.row(m.n[0]), x.row(m.n[1]), x.row(m.n[2])};
    Vec3 f[3];
    w[e] = membrane_element(m, law_, xe, f);
    A[e] = m.A0;
  }
  nodal_average(topo_, w, A, Em);
  Eb = Eigen::VectorXd::Zero(topo_.n_nodes);
  Esh = Eigen::VectorXd::Zero(topo_.n_nodes);
}

}  // namespace capsflow::shell
