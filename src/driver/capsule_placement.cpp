#include "capsflow/core/driver/capsule_placement.hpp"

#include <fmt/core.h>

#include <stdexcept>

#include "capsflow/core/bie/cross_near_field.hpp"

namespace capsflow {

SurfaceSet place_capsules(const Scene& scene, const SurfaceMesh& one) {
  std::vector<SurfaceMesh> parts;
  for (const Vec3& c : scene.capsule_centers()) {
    SurfaceMesh m = one;
    if (!c.isZero()) m.vertices.rowwise() += c.transpose();  // zero: untouched (−0.0 stays −0.0)
    parts.push_back(std::move(m));
  }
  return SurfaceSet(parts);
}

namespace {

std::string what_to_change(const Scene& scene, int moved) {
  return scene.capsules.empty() ? std::string("lengthen the step layout.dx, dy, dz")
                                : fmt::format("move capsule {}'s center", moved + 1);
}

}  // namespace

void check_capsules_apart(const Scene& scene, const SurfaceSet& set) {
  if (set.size() < 2) return;
  const Points& x = set.mesh().vertices;
  CrossNearField cross(set);
  cross.find_pairs(x);
  if (cross.inside_nodes() > 0) {
    const SurfaceGap& g = cross.deepest_inside();
    const int a = std::min(g.part, g.other), b = std::max(g.part, g.other);
    throw SceneError(fmt::format("capsules {} and {} overlap where they start ({} node(s) of one inside the other): {}",
                                            a + 1, b + 1, cross.inside_nodes(), what_to_change(scene, b)));
  }
}

}  // namespace capsflow
