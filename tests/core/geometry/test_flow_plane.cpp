// The flow-plane observables against exact geometry and motion: the plane and sense of the two
// standard flows, the inclination and in-plane Taylor parameter of rotated ellipsoids (exact for
// affine images of the subdivided sphere), and the tank-treading rate of prescribed material
// motions (rigid rotations, and Keller–Skalak tank-treading on a fixed ellipsoid).
#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/Geometry>

#include "capsflow/core/geometry/flow_plane.hpp"
#include "capsflow/core/mesh/generation.hpp"

using namespace capsflow;

namespace {
Mat3 simple_shear() {
  Mat3 L = Mat3::Zero();
  L(0, 1) = 1;
  return L;
}
Mat3 rotation_z(double angle) { return Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix(); }
// An ellipsoid with semi-axes ∝ (a, b, b) along (x1, x2, x3), turned by `angle` about x3.
SurfaceMesh ellipsoid(double aspect, double angle, int level = 3) {
  SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, level);
  map_to_spheroid(m, aspect, 0);
  m.vertices = m.vertices * rotation_z(angle).transpose();
  return m;
}
}  // namespace

TEST(FlowPlane, StandardFlows) {
  const FlowPlane s = flow_plane(simple_shear());  // v = x2 e1: plane x1x2, vorticity −x3
  EXPECT_LT((s.normal - Vec3::UnitZ()).norm(), 1e-15);
  EXPECT_LT((s.e1 - Vec3::UnitX()).norm(), 1e-15);
  EXPECT_LT((s.e2 - Vec3::UnitY()).norm(), 1e-15);
  EXPECT_EQ(s.sense, -1.0);
  const FlowPlane h = flow_plane(Vec3(1, 0, -1).asDiagonal());  // planar hyperbolic: plane x1x3
  EXPECT_LT((h.normal - Vec3::UnitY()).norm(), 1e-15);
  EXPECT_LT((h.e1 - Vec3::UnitX()).norm(), 1e-15);
  EXPECT_EQ(h.sense, 1.0);  // no vorticity
  const FlowPlane q = flow_plane(Mat3::Zero());  // no flow: x1x2
  EXPECT_EQ(q.normal, Vec3::UnitZ());
}

TEST(FlowPlane, InclinationAndTaylorParameterOfRotatedEllipsoids) {
  const FlowPlane p = flow_plane(simple_shear());
  for (double aspect : {1.2, 2.0})
    for (double angle : {0.0, 0.3, M_PI / 4, -1.2}) {
      const InPlaneShape s = in_plane_shape(ellipsoid(aspect, angle), p);
      // Volume moments of an affine image of the centrally symmetric subdivided icosahedron are
      // exact (docs/conventions.md §5.2): D and θ to round-off.
      EXPECT_NEAR(s.D, (aspect - 1) / (aspect + 1), 1e-12) << aspect << " " << angle;
      EXPECT_NEAR(s.theta, angle, 1e-12) << aspect << " " << angle;
    }
}

TEST(FlowPlane, TankTreadingRateOfRigidRotations) {
  // Every material point turns by α about x3 in Δt: the rate is α/Δt, in the flow's sense
  // (simple shear turns clockwise, −x3): the sphere (tank-treading at the vorticity rate 1/2 when
  // α = −Δt/2) and a tumbling ellipsoid (the frame turns with it).
  const FlowPlane p = flow_plane(simple_shear());
  for (double aspect : {1.0, 2.0}) {
    TankTreadingMeter meter(p);
    const SurfaceMesh m0 = ellipsoid(aspect, 0.2);
    EXPECT_TRUE(std::isnan(meter.update(m0, 1.0)));  // no previous output
    const double dt = 0.3, alpha = -0.5 * dt;
    SurfaceMesh m1 = m0;
    m1.vertices = m0.vertices * rotation_z(alpha).transpose();
    EXPECT_NEAR(meter.update(m1, 1.0 + dt), 0.5, 1e-12) << aspect;
  }
}

TEST(FlowPlane, TankTreadingRateOfKellerSkalakMotion) {
  // Material points of a fixed ellipsoid (semi-axes a, b in the plane, inclined by θ) advance their
  // elliptic phase ψ uniformly, x' = (a cos ψ, b sin ψ) in the ellipse frame (Keller & Skalak 1982):
  // Δψ = −ω Δt for a clockwise tank-treading rate ω. The moved nodes describe the same ellipsoid, but
  // its volume moments (hence a, b, θ) change slightly with the redistributed vertices.
  const FlowPlane p = flow_plane(simple_shear());
  const double theta = 0.4, omega = 0.37, dt = 0.2;
  const SurfaceMesh m0 = ellipsoid(1.8, theta, 4);
  const InPlaneShape s = in_plane_shape(m0, p);
  SurfaceMesh m1 = m0;
  const Mat3 R = rotation_z(theta);
  for (Eigen::Index i = 0; i < m0.vertices.rows(); ++i) {
    const Vec3 x = R.transpose() * (m0.vertices.row(i).transpose() - s.centroid);  // ellipse frame
    const double psi = std::atan2(x.y() / s.b, x.x() / s.a), rho = std::hypot(x.x() / s.a, x.y() / s.b);
    const double psi1 = psi - omega * dt;
    m1.vertices.row(i) = (s.centroid + R * Vec3(s.a * rho * std::cos(psi1), s.b * rho * std::sin(psi1), x.z())).transpose();
  }
  TankTreadingMeter meter(p);
  meter.update(m0, 0.0);
  // Measured within 1e-8 relative (the redistributed nodes change the moments very little).
  EXPECT_NEAR(meter.update(m1, dt), omega, 1e-6 * omega);
}
