#pragma once
// Geometry and shape diagnostics of a closed, outward-oriented triangulated surface
// (P1 geometry: flat facets). Conventions: docs/conventions.md §4–5. All lengths in units of ℓ.
#include <array>

#include "capsflow/core/types.hpp"

namespace capsflow {

// Per-element area and unit normal (outward for an outward-oriented mesh).
Eigen::VectorXd element_areas(const SurfaceMesh& mesh);
Points element_normals(const SurfaceMesh& mesh);
// Area-weighted average of the normals of the elements around each node, normalised
// (shell::area_weighted_normals, the formula of the wall's reference directors).
Points nodal_normals(const SurfaceMesh& mesh);
// One third of the area of the elements around each node (row sums of the mass matrix).
Eigen::VectorXd nodal_areas(const SurfaceMesh& mesh);
Eigen::VectorXd nodal_areas(const Points& x, const Triangles& triangles);  // the same, without a copy of x

double surface_area(const SurfaceMesh& mesh);
double enclosed_volume(const SurfaceMesh& mesh);
inline double equivalent_radius(double volume) { return std::cbrt(3.0 * volume / (4.0 * M_PI)); }

// Volume moments of the enclosed solid: V, centroid c, central second moment
// Σ = ∫(x − c)(x − c)ᵀ dV (exact for the polyhedron; divergence theorem per facet).
struct VolumeMoments {
  double volume = 0;
  Vec3 centroid = Vec3::Zero();
  Mat3 second_moment = Mat3::Zero();
};
VolumeMoments volume_moments(const SurfaceMesh& mesh);
VolumeMoments volume_moments(const Points& x, const Triangles& triangles);  // the same, without a copy of x
// The rate of change of volume_moments(x).centroid when the nodes move with velocities v: its exact
// derivative along v (the velocity of the polyhedron's volume centroid).
Vec3 centroid_rate(const Points& x, const Triangles& triangles, const Points& v);

// Actual half-extents L_i of the surface along x_i: the paper's
// Table 1 "L_i" = half of (max − min) of the vertex coordinates (exact for P1 geometry).
Vec3 half_extents(const SurfaceMesh& mesh);

}  // namespace capsflow
