#include "capsflow/shell/director.hpp"

#include <cmath>

#include "capsflow/shell/parallel_thresholds.hpp"

namespace capsflow::shell {

void tangent_basis(const Vec3& d, Vec3& t1, Vec3& t2) {
  int k = 0;
  if (std::abs(d[1]) < std::abs(d[k])) k = 1;
  if (std::abs(d[2]) < std::abs(d[k])) k = 2;
  Vec3 e = Vec3::Zero();
  e[k] = 1.0;
  t1 = (e - e.dot(d) * d).normalized();
  t2 = d.cross(t1);
}

NodalTriads::NodalTriads(const Points& directors) {
  const Eigen::Index n = directors.rows();
  d.resize(n, 3);
  t1.resize(n, 3);
  t2.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Vec3 di = directors.row(i).normalized();
    Vec3 a, b;
    tangent_basis(di, a, b);
    d.row(i) = di;
    t1.row(i) = a;
    t2.row(i) = b;
  }
}

void area_weighted_normals(const Points& x, const Topology& topo, Points& nrm) {
  const int n = topo.n_nodes;
  if (nrm.rows() != n) nrm.resize(n, 3);
#pragma omp parallel for schedule(static) if (n > kParallelNodes)
  for (int i = 0; i < n; ++i) nrm.row(i) = area_weighted_normal(x, topo, i).transpose();
}

Points area_weighted_normals(const Points& x, const Triangles& tri) {
  Points n;
  area_weighted_normals(x, Topology(tri, x.rows()), n);
  return n;
}

}  // namespace capsflow::shell
