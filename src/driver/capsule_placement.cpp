#include "capsflow/core/driver/capsule_placement.hpp"

#include <fmt/core.h>

#include <algorithm>

#include <stdexcept>

#include "capsflow/core/bie/cross_near_field.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/rhs/wall_factory.hpp"

namespace capsflow {

SurfaceSet place_capsules(const Scene& scene) {
  const SurfaceMesh shared = make_reference_mesh(scene.mesh);
  std::vector<SurfaceMesh> parts;
  const std::vector<Vec3> centers = scene.capsule_centers();
  for (std::size_t k = 0; k < centers.size(); ++k) {
    const Vec3& c = centers[k];
    const bool own = k < scene.capsules.size() && scene.capsules[k].mesh;
    SurfaceMesh m = own ? make_reference_mesh(*scene.capsules[k].mesh) : shared;
    m.vertices = stretched_nodes(m, scene.capsule_scene(static_cast<int>(k)).wall.initial_stretch);
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

ChannelFlow channel_flow_of(const Scene& scene, const SurfaceMesh& capsule) {
  const ChannelSpec& c = scene.channel;
  ChannelFlow out;
  out.geometry.shape = c.shape == ChannelKind::Tube         ? ChannelShape::Tube
                       : c.shape == ChannelKind::SquareDuct ? ChannelShape::SquareDuct
                                                            : ChannelShape::ConstrictedDuct;
  out.geometry.radius = c.radius;
  out.geometry.length = c.length;
  const double edge = mesh_stats(capsule).edge_mean;
  out.geometry.element_size = c.element_size_auto ? std::max(edge, c.radius / 8) : c.element_size;
  const double h = out.geometry.element_size;
  if (h > 4 * edge)
    throw SceneError(fmt::format("channel.element_size: {:.4g} is more than 4 times the capsule's mean edge {:.4g}", h, edge));
  if (h > c.radius)
    throw SceneError(fmt::format("channel.element_size: {:.4g} is larger than channel.radius = {:.4g}", h, c.radius));
  double reach = 0, x_min = capsule.vertices.col(0).minCoeff(), x_max = capsule.vertices.col(0).maxCoeff();
  for (Eigen::Index i = 0; i < capsule.num_nodes(); ++i)
    reach = std::max(reach, distance_from_axis(out.geometry, capsule.vertices(i, 1), capsule.vertices(i, 2)));
  if (reach > c.radius - 0.1 * h)
    throw SceneError(fmt::format("channel.radius: {:.4g} is too small: the capsule reaches {:.4g} from the axis, and must "
                                 "start at least a tenth of a wall element ({:.3g}) inside the wall",
                                 c.radius, reach, 0.1 * h));
  const double needed = 2 * std::max(std::abs(x_min), std::abs(x_max)) + 4 * c.radius;
  if (c.length < needed)
    throw SceneError(fmt::format("channel.length: {:.4g} is too short: the capsule spans x1 in [{:.3g}, {:.3g}] and its "
                                 "disturbance needs 2 radii to each cap: at least {:.4g}",
                                 c.length, x_min, x_max, needed));
  if (out.geometry.shape != ChannelShape::ConstrictedDuct) return out;
  ChannelGeometry& g = out.geometry;
  g.constriction_height = c.constriction_height * c.radius;
  g.constriction_width = c.constriction_width * c.radius;
  g.constriction_length = c.constriction_length * c.radius;
  g.constriction_center = c.constriction_center * c.radius;
  g.constriction_taper = c.constriction_taper_auto ? h : c.constriction_taper * c.radius;
  const double start = g.constriction_center - 0.5 * g.constriction_length - g.constriction_taper;
  const double end = g.constriction_center + 0.5 * g.constriction_length + g.constriction_taper;
  if (start < -0.5 * c.length + 2 * c.radius || end > 0.5 * c.length - 2 * c.radius)
    throw SceneError(fmt::format("channel.constriction_center: the constriction and its tapers span x1 in [{:.3g}, {:.3g}], "
                                 "which must end 2 radii ({:.3g}) from each cap at x1 = ±{:.3g} (its disturbance decays "
                                 "there)", start, end, 2 * c.radius, 0.5 * c.length));
  if (x_max > start - 0.1 * h)
    throw SceneError(fmt::format("channel.constriction_center: the capsule reaches x1 = {:.3g}, and must start upstream of "
                                 "the constriction, which begins at x1 = {:.3g}", x_max, start));
  return out;
}

}  // namespace capsflow
