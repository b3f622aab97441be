#include "capsflow/core/health/run_health.hpp"

#include <cmath>
#include <fmt/core.h>

namespace capsflow {

std::string check_health(const SurfaceMesh& before, const Points& after, double volume_drift, double max_volume_drift) {
  for (Eigen::Index i = 0; i < after.rows(); ++i)
    if (!after.row(i).allFinite()) return fmt::format("non-finite position at node {}", i);
  const Triangles& tri = before.triangles;
  for (Eigen::Index e = 0; e < tri.rows(); ++e) {
    const int a = tri(e, 0), b = tri(e, 1), c = tri(e, 2);
    const Vec3 n0 = (before.vertices.row(b) - before.vertices.row(a)).cross(before.vertices.row(c) - before.vertices.row(a));
    const Vec3 n1 = (after.row(b) - after.row(a)).cross(after.row(c) - after.row(a));
    if (n1.norm() < kCollapsedAreaRatio * n0.norm()) return fmt::format("element {} collapsed (area ratio {:.1e} in one step)", e, n1.norm() / n0.norm());
    if (n0.dot(n1) <= 0) return fmt::format("element {} inverted (its normal flipped in one step)", e);
  }
  if (!(std::abs(volume_drift) <= max_volume_drift))
    return fmt::format("volume drift {:.3g} exceeds {:.3g} (runaway)", volume_drift, max_volume_drift);
  return {};
}

}  // namespace capsflow
