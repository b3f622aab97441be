#include "capsflow/core/geometry/rear_pole.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <vector>

#include "capsflow/core/geometry/measures.hpp"

namespace capsflow {

double rear_pole_curvature(const Points& x, const Triangles& triangles) {
  const Vec3 c = volume_moments(x, triangles).centroid;
  double edge = 0;
  for (Eigen::Index e = 0; e < triangles.rows(); ++e)
    for (int k = 0; k < 3; ++k) edge += (x.row(triangles(e, k)) - x.row(triangles(e, (k + 1) % 3))).norm();
  edge /= 3.0 * static_cast<double>(triangles.rows());
  Eigen::Index pole = -1;
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    if (x(i, 0) >= c.x()) continue;
    const double d = std::hypot(x(i, 1) - c.y(), x(i, 2) - c.z());
    if (d < best) best = d, pole = i;
  }
  if (pole < 0) return std::numeric_limits<double>::quiet_NaN();
  const Vec3 p = x.row(pole).transpose();
  std::vector<Eigen::Index> near;
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    if (x(i, 0) < c.x() && std::hypot(x(i, 1) - p.y(), x(i, 2) - p.z()) < 2.5 * edge) near.push_back(i);
  if (near.size() < 6) return std::numeric_limits<double>::quiet_NaN();
  Eigen::MatrixXd A(static_cast<Eigen::Index>(near.size()), 4);
  Eigen::VectorXd b(static_cast<Eigen::Index>(near.size()));
  for (std::size_t k = 0; k < near.size(); ++k) {
    const double dy = x(near[k], 1) - p.y(), dz = x(near[k], 2) - p.z();
    A.row(static_cast<Eigen::Index>(k)) << 1, dy, dz, 0.5 * (dy * dy + dz * dz);
    b[static_cast<Eigen::Index>(k)] = x(near[k], 0) - p.x();
  }
  return A.colPivHouseholderQr().solve(b)[3];
}

}  // namespace capsflow
