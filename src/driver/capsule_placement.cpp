#include "capsflow/core/driver/capsule_placement.hpp"

#include <fmt/core.h>

#include <algorithm>

#include <stdexcept>

#include "capsflow/core/bie/cross_near_field.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"

namespace capsflow {

SurfaceSet place_capsules(const Scene& scene) {
  const SurfaceMesh shared = make_reference_mesh(scene.mesh);
  std::vector<SurfaceMesh> parts;
  const std::vector<Vec3> centers = scene.capsule_centers();
  for (std::size_t k = 0; k < centers.size(); ++k) {
    const Vec3& c = centers[k];
    const bool own = k < scene.capsules.size() && scene.capsules[k].mesh;
    SurfaceMesh m = own ? make_reference_mesh(*scene.capsules[k].mesh) : shared;
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
