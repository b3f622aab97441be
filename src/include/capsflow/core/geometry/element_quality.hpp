#pragma once
// Element quality and in-plane deformation of the wall's facets against the reference mesh:
// what a health monitor reports before elements degenerate (docs/health-monitors.md).
#include <vector>

#include "capsflow/core/types.hpp"

namespace capsflow {

// Principal stretches λ1 ≥ λ2 of the linear map taking reference facet (A, B, C) to current facet
// (a, b, c): the square roots of the eigenvalues of G⁻¹g, G and g the covariant metrics of the
// edge vectors (B − A, C − A) and (b − a, c − a).
struct PrincipalStretches {
  double l1 = 1, l2 = 1;
};
PrincipalStretches principal_stretches(const Vec3& A, const Vec3& B, const Vec3& C, const Vec3& a, const Vec3& b,
                                       const Vec3& c);

struct ElementQuality {
  double min_angle_deg = 60;      // smallest interior angle of any facet
  double max_aspect_ratio = 1;    // longest edge / (2√3 × inradius): 1 for an equilateral facet
  double max_stretch_ratio = 1;   // largest λ1/λ2 against the reference facet
  double max_stretch = 1, min_stretch = 1;  // largest λ1 and smallest λ2
};
ElementQuality element_quality(const SurfaceMesh& reference, const Points& x);

}  // namespace capsflow
