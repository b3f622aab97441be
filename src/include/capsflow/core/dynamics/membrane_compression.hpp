#pragma once
// Compressive membrane tension: where the smaller principal Cauchy tension of the wall's in-plane
// law is negative. A membrane without bending stiffness cannot carry compression: there it
// wrinkles, and on a discrete mesh at the wavelength of the mesh (docs/health-monitors.md).
#include "capsflow/core/types.hpp"
#include "capsflow/shell/laws.hpp"

namespace capsflow {

struct MembraneCompression {
  double compressed_area_fraction = 0;  // deformed area with T2 < 0, over the total
  double min_tension = 0;               // most negative T2 (0 if none), in units of G_s
  Vec3 where = Vec3::Zero();            // centroid of the facet with the most negative T2
};
MembraneCompression membrane_compression(const SurfaceMesh& reference, const Points& x, const shell::MembraneLaw& law);

}  // namespace capsflow
