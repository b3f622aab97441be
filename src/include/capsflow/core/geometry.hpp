#pragma once
// Geometry and shape diagnostics of a closed, outward-oriented triangulated surface
// (P1 geometry: flat facets). Conventions: design.md §2. All lengths in units of ℓ.
#include <Eigen/Sparse>
#include <array>

#include "capsflow/core/types.hpp"

namespace capsflow {

// Per-element area and unit normal (outward for an outward-oriented mesh).
Eigen::VectorXd element_areas(const SurfaceMesh& mesh);
Points element_normals(const SurfaceMesh& mesh);
// Area-weighted average of the normals of the elements around each node, normalised.
Points nodal_normals(const SurfaceMesh& mesh);
// One third of the area of the elements around each node (row sums of the mass matrix).
Eigen::VectorXd nodal_areas(const SurfaceMesh& mesh);

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

// The ellipsoid with the same volume second moments (numerics.md §5.3): semi-axes
// Le_i = sqrt(5 σ_i / V). Axis i is the principal axis most aligned with coordinate axis x_i,
// so that Le = (Le1, Le2, Le3) is comparable to the paper's Table 1; axes(:, i) is its direction.
struct InertiaEllipsoid {
  Vec3 semi_axes = Vec3::Zero();  // Le1, Le2, Le3
  Mat3 axes = Mat3::Identity();   // columns: unit principal directions
  Vec3 centroid = Vec3::Zero();
};
InertiaEllipsoid inertia_ellipsoid(const SurfaceMesh& mesh);

// Taylor deformation D_ij = (Le_i − Le_j)/(Le_i + Le_j) (paper Eq. 40).
struct TaylorDeformation {
  double D12 = 0, D13 = 0, D23 = 0;
};
TaylorDeformation taylor_deformation(const InertiaEllipsoid& e);

// Actual half-extents L_i of the surface along x_i: the paper's
// Table 1 "L_i" = half of (max − min) of the vertex coordinates (exact for P1 geometry).
Vec3 half_extents(const SurfaceMesh& mesh);

// Consistent P1 mass matrix M_ij = ∫ φ_i φ_j dS on the given (current) surface, N×N
// (the same matrix acts on each Cartesian component).
Eigen::SparseMatrix<double> mass_matrix(const SurfaceMesh& mesh);

}  // namespace capsflow
