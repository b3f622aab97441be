#include "capsflow/core/mesh/biconcave.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace capsflow {

void map_to_biconcave(SurfaceMesh& mesh, double radius, int axis, const BiconcaveCoefficients& c) {
  if (!(radius > 0) || !std::isfinite(radius))
    throw std::invalid_argument("biconcave disc radius must be a positive finite number");
  if (axis < 0 || axis > 2) throw std::invalid_argument("biconcave disc axis must be 1, 2 or 3");
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    auto x = mesh.vertices.row(i);
    const double n = x.norm();
    if (!(std::abs(n - 1.0) < 1e-9))
      throw std::invalid_argument("map_to_biconcave needs a unit-sphere mesh (vertex at radius " + std::to_string(n) + ")");
    const double z = x(axis) / n;
    const double rho2 = std::max(0.0, 1.0 - z * z);  // ρ² of the disc = the sphere's in-plane radius squared
    for (int k = 0; k < 3; ++k)
      if (k != axis) x(k) *= radius / n;
    x(axis) = 0.5 * radius * z * (c.c0 + c.c1 * rho2 + c.c2 * rho2 * rho2);
  }
}

}  // namespace capsflow
