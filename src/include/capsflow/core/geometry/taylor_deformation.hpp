#pragma once
// Taylor deformation of a closed surface from the ellipsoid with the same volume inertia
// (paper Eq. 40, Table 1 columns Le_i). Conventions: docs/conventions.md §5.
#include "capsflow/core/geometry/measures.hpp"

namespace capsflow {

// The ellipsoid with the same volume second moments (docs/conventions.md §5.2): semi-axes
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

}  // namespace capsflow
