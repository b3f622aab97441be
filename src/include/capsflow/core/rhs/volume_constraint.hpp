#pragma once
// The enclosed volume as a constraint on the node positions (viscosity ratio 1: the inner and
// outer fluids are incompressible, so the capsule's volume is exactly conserved).
//   ∂V/∂x_i = a_i = Σ_{e∋i} A_e n_e / 3  (exact for the polyhedron), so dV/dt = Σ_i a_i·v_i.
// - remove_normal_flux: v_i ← v_i − c a_i/|a_i| with c = Σ a_i·v_i / Σ|a_i| — zero discrete flux,
//   by a uniform normal speed (applied to every right-hand side with fluid.volume_correction);
// - project_volume: x_i ← x_i + δ a_i/|a_i| with δ from Newton on V(x) = V_target — the same
//   uniform normal displacement, removing what a large time step adds (the integrator's O(τ³)
//   per step; Hairer, Lubich & Wanner, Geometric Numerical Integration, §IV.4: standard
//   projection onto an invariant).
#include <vector>

#include "capsflow/core/geometry/surface_set.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

// a_i for every node (N×3), into `a`.
void volume_gradient(const Points& x, const Triangles& tri, Points& a);
// v ← v − c a/|a| (a from volume_gradient) with zero flux afterwards.
void remove_normal_flux(const Points& a, Points& v);
// Moves x along a/|a| until |V − target| ≤ 1e-14 target (≤ 3 Newton steps); returns |δ| summed.
double project_volume(Points& x, const Triangles& tri, double target, Points& scratch);

// project_volume on each surface of a set, onto its own target (several capsules: each keeps its
// volume, not only their sum). Returns |δ| summed over the surfaces.
class VolumeProjection {
 public:
  VolumeProjection(const SurfaceSet& surfaces, std::vector<double> targets);
  double apply(Points& x);

 private:
  std::vector<SurfacePart> parts_;
  std::vector<Triangles> triangles_;  // each surface's, in its own numbering
  std::vector<double> targets_;
  Points part_, scratch_;
};

}  // namespace capsflow
