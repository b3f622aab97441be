#include "capsflow/shell/director.hpp"

#include <cmath>

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

Points area_weighted_normals(const Points& X, const Triangles& tri) {
  Points n = Points::Zero(X.rows(), 3);
  for (Eigen::Index e = 0; e < tri.rows(); ++e) {
    const Vec3 a = X.row(tri(e, 0)), b = X.row(tri(e, 1)), c = X.row(tri(e, 2));
    const Vec3 an = (b - a).cross(c - a);  // 2 x area x unit normal
    for (int k = 0; k < 3; ++k) n.row(tri(e, k)) += an.transpose();
  }
  for (Eigen::Index i = 0; i < n.rows(); ++i) {
    const double l = n.row(i).norm();
    if (l > 0) n.row(i) /= l;
  }
  return n;
}

}  // namespace capsflow::shell
