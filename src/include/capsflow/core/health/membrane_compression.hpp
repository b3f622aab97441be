#pragma once
// Compressive membrane tension: where the smaller principal Cauchy tension of the wall's in-plane
// law is negative. A membrane without bending stiffness cannot carry compression: there it
// wrinkles, and on a discrete mesh at the wavelength of the mesh (docs/health-monitors.md).
#include "capsflow/core/types.hpp"
#include "capsflow/shell/laws.hpp"

namespace capsflow {

// The undeformed wall has T = 0 up to round-off in the stretches (≈ 1e-8 G_s measured on a level-4
// sphere): tensions above −1e-6 G_s are not compression.
inline constexpr double kCompressionRoundOff = 1e-6;

struct MembraneCompression {
  double compressed_area_fraction = 0;  // deformed area with T2 < 0, over the total
  double min_tension = 0;               // most negative T2 (0 if none), in units of G_s
  Vec3 where = Vec3::Zero();            // centroid of the facet with the most negative T2
  // Most negative T2 (0 if none, tensions above −kCompressionRoundOff count as none) over the facets whose centroid lies within `probe_radius` of
  // `probe` (both given to membrane_compression; 0 without a probe): is the wall compressed there?
  double min_tension_near_probe = 0;
};
// probe_radius ≤ 0: no probe.
MembraneCompression membrane_compression(const SurfaceMesh& reference, const Points& x, const shell::MembraneLaw& law,
                                         const Vec3& probe = Vec3::Zero(), double probe_radius = 0);

}  // namespace capsflow
