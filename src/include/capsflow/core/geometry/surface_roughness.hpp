#pragma once
// Mesh-scale roughness of the wall (the buckling monitor of docs/health-monitors.md):
// - facet angles: the angle between the normals of two facets sharing an edge. A smooth surface
//   discretised with edge h and curvature radius R has angles ≈ h/R; a wall that buckles at the
//   mesh scale folds facet against facet (tens of degrees).
// - grid-scale oscillation: c = (U x)·n is the umbrella vector's normal part, ≈ h² H/2 on a smooth
//   surface (H the mean curvature), so it varies smoothly; a fold resolved by many elements keeps
//   it smooth too. High-passing it once more, |U c|/h, removes the resolved curvature and leaves
//   the amplitude of the two-element-wavelength wiggle relative to the element size: ≈ 0.003 on
//   an icosphere (its 5-valent nodes), ≈ 0.5 on a wall that has buckled at the mesh scale.
#include <array>
#include <vector>

#include "capsflow/core/geometry/umbrella.hpp"
#include "capsflow/core/types.hpp"
#include "capsflow/shell/topology.hpp"

namespace capsflow {

struct SurfaceRoughness {
  double facet_angle_max = 0;       // degrees, over all interior edges
  double facet_angle_p99 = 0;       // degrees, 99th percentile over edges
  double grid_oscillation_max = 0;  // max over nodes of |U c|/h (dimensionless)
  double grid_oscillation_p99 = 0;  // 99th percentile over nodes
  Vec3 worst_position = Vec3::Zero();  // node with the largest grid-scale oscillation
};

class RoughnessMeter {
 public:
  explicit RoughnessMeter(const Triangles& triangles, Eigen::Index num_nodes);
  SurfaceRoughness measure(const Points& x) const;

 private:
  Triangles tri_;
  shell::Topology topo_;  // node–element incidence of the area-weighted normals
  UmbrellaOperator umbrella_;
  std::vector<std::array<int, 2>> edge_faces_;  // the two facets of each edge
  mutable Points ux_, normals_;       // scratch of measure(), kept between calls
  mutable Eigen::VectorXd c_, uc_;
  mutable std::vector<double> angles_, osc_;
};

// The q-quantile (0 ≤ q ≤ 1, nearest rank) of values; reorders values. 0 for an empty vector.
double quantile(std::vector<double>& values, double q);

}  // namespace capsflow
