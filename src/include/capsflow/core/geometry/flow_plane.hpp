#pragma once
// The capsule seen in the flow plane (docs/conventions.md §5.6): the inclination θ of its major
// axis, the in-plane Taylor parameter, and the membrane's tank-treading rate from the motion of
// its material points — the observables of viscosity-ratio studies.
//
// The flow plane of v∞ = L x is normal to its neutral direction, the unit vector n that minimises
// |L n|² + |Lᵀ n|² (x3 for simple shear, x2 for planar hyperbolic flow, x3 when L = 0). In it, e1
// is x1 projected on the plane (the flow or extension direction) and e2 = n × e1. The shape in the
// plane is the ellipse of the volume second moments restricted to it (as the inertia ellipsoid of
// docs/conventions.md §5.2, semi-axes proportional to √σ).
#include <limits>

#include "capsflow/core/types.hpp"

namespace capsflow {

struct FlowPlane {
  Vec3 e1 = Vec3::UnitX(), e2 = Vec3::UnitY(), normal = Vec3::UnitZ();
  // Rotations are reported positive in the sense of the flow's vorticity about `normal` (+1), or
  // the opposite sense (−1); +1 when the flow has no vorticity along the normal.
  double sense = 1;
};
FlowPlane flow_plane(const Mat3& L);

struct InPlaneShape {
  double a = 1, b = 1;     // major and minor semi-axes √(5σ/V), σ the in-plane second moments
  double D = 0;            // in-plane Taylor parameter (a − b)/(a + b)
  double theta = 0;        // inclination of the major axis from e1 towards e2, in (−π/2, π/2]
  Vec3 centroid = Vec3::Zero();
};
InPlaneShape in_plane_shape(const SurfaceMesh& mesh, const FlowPlane& plane);

// The rotation rate of the membrane's material points in the flow plane between two output times.
// Every node's elliptic phase Ψ = θ + atan2(η/b, ξ/a), (ξ, η) its in-plane coordinates in the
// ellipse's frame, advances at one rate ω for all points of a membrane that tank-treads on a
// steady ellipsoid (Keller & Skalak 1982), and Ψ stays continuous where a = b (on a sphere it is
// the polar angle). rate = sense × the mean of ΔΨ/Δt over the nodes, ΔΨ wrapped to (−π, π] and
// weighted by the squared in-plane elliptic radii at both times (the phase is ill-defined near
// the axis). On a steady tank-treading shape (dθ/dt = 0) it is the tank-treading frequency ω,
// 1/2 for a sphere in simple shear; on a rigidly tumbling body, its tumbling rate (Ψ includes the
// frame's rotation).
class TankTreadingMeter {
 public:
  explicit TankTreadingMeter(const FlowPlane& plane) : plane_(plane) {}
  // The rate since the previous call (NaN on the first call, or when t did not advance). Outputs
  // must be closer than π/|rate| (6.3 for a sphere in simple shear) for ΔΨ to be unambiguous.
  double update(const SurfaceMesh& mesh, double t);

 private:
  FlowPlane plane_;
  Eigen::VectorXd phase_, weight_;
  double t_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace capsflow
