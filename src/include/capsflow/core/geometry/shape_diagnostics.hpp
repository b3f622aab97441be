#pragma once
// Shape diagnostics at an output time (paper Eq. 40, Table 1): Taylor deformation, inertia
// ellipsoid semi-axes Le_i, half-extents L_i, area and volume.
#include "capsflow/core/geometry/taylor_deformation.hpp"

namespace capsflow {

struct ShapeDiagnostics {
  TaylorDeformation D;
  Vec3 Le = Vec3::Zero();  // inertia-ellipsoid semi-axes
  Vec3 L = Vec3::Zero();   // half-extents of the surface
  double area = 0, volume = 0;
};
ShapeDiagnostics shape_diagnostics(const SurfaceMesh& current);

}  // namespace capsflow
