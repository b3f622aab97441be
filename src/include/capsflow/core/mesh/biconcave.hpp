#pragma once
// The biconcave disc of a resting human red blood cell (Evans & Fung 1972, in the form used by most
// cell-flow codes): the surface of revolution
//
//     z(r) = ± (R/2) · sqrt(1 − ρ²) · (C0 + C1 ρ² + C2 ρ⁴),   ρ = r/R ≤ 1,
//
// C0 = 0.2072, C1 = 2.0026, C2 = −1.1228 (R = 3.91 µm: volume ≈ 94 µm³, area ≈ 135 µm²).
// docs/conventions.md §4.2.1.
#include "capsflow/core/types.hpp"

namespace capsflow {

// The Evans–Fung coefficients, in units of the disc radius R.
struct BiconcaveCoefficients {
  double c0 = 0.2072, c1 = 2.0026, c2 = -1.1228;
};

// Maps a unit-sphere mesh point by point onto the biconcave disc of radius `radius` whose symmetry
// axis is `axis` (0, 1 or 2): with ρ² = 1 − X_axis² the in-plane coordinates are scaled by R and
// X_axis = ± sqrt(1 − ρ²) becomes (R/2) X_axis (C0 + C1 ρ² + C2 ρ⁴), so every vertex lands on the
// surface and the map is smooth (a polynomial). Centrally symmetric meshes stay so. No scaling to
// ℓ = 1 (scale_to_unit_equivalent_radius does that).
void map_to_biconcave(SurfaceMesh& mesh, double radius, int axis, const BiconcaveCoefficients& c = {});

}  // namespace capsflow
