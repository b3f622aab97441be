#include "capsflow/core/bie/curved_triangle.hpp"

namespace capsflow {

void vertex_normals_max(const Points& x, const Triangles& t, Points& n) {
  n.setZero(x.rows(), 3);  // no reallocation when n already has the size
  for (Eigen::Index e = 0; e < t.rows(); ++e)
    for (int k = 0; k < 3; ++k) {
      const int i = t(e, k), j = t(e, (k + 1) % 3), l = t(e, (k + 2) % 3);
      const Vec3 e1 = x.row(j) - x.row(i), e2 = x.row(l) - x.row(i);
      n.row(i) += (e1.cross(e2) / (e1.squaredNorm() * e2.squaredNorm())).transpose();
    }
  for (Eigen::Index i = 0; i < n.rows(); ++i) n.row(i).normalize();
}

}  // namespace capsflow
