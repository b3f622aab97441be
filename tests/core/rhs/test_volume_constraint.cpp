// The volume constraint on its own (rhs/volume_constraint.hpp): the volume gradient against finite
// differences of the enclosed volume, the flux removal, and the projection onto a target volume.
#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/rhs/volume_constraint.hpp"

using namespace capsflow;

namespace {
// A sphere mesh with a smooth, non-symmetric perturbation: no gradient vanishes by symmetry.
SurfaceMesh bumpy_sphere() {
  SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 2);
  for (Eigen::Index i = 0; i < m.vertices.rows(); ++i) {
    const Vec3 p = m.vertices.row(i);
    m.vertices.row(i) = (1.0 + 0.1 * p.x() * p.y() + 0.05 * p.z()) * p.transpose();
  }
  return m;
}
}  // namespace

TEST(VolumeConstraint, GradientIsTheDerivativeOfTheEnclosedVolume) {
  SurfaceMesh m = bumpy_sphere();
  Points a;
  volume_gradient(m.vertices, m.triangles, a);
  // V is a cubic polynomial in each coordinate: the central difference is exact up to h² V''' = 0
  // in the leading term; round-off ε V / h ≈ 4e-16 · 4 / 1e-5 ≈ 2e-10.
  const double h = 1e-5;
  for (Eigen::Index i : {0L, 7L, 41L, 100L}) {
    for (int c = 0; c < 3; ++c) {
      SurfaceMesh p = m, q = m;
      p.vertices(i, c) += h;
      q.vertices(i, c) -= h;
      const double fd = (enclosed_volume(p) - enclosed_volume(q)) / (2 * h);
      EXPECT_NEAR(a(i, c), fd, 1e-9) << "node " << i << ", component " << c;
    }
  }
}

TEST(VolumeConstraint, FluxRemovalLeavesZeroFluxByAUniformNormalSpeed) {
  const SurfaceMesh m = bumpy_sphere();
  Points a;
  volume_gradient(m.vertices, m.triangles, a);
  Points v(m.vertices.rows(), 3);
  for (Eigen::Index i = 0; i < v.rows(); ++i) v.row(i) << 0.3 + std::sin(i), std::cos(2.0 * i), 0.2;  // net outflow
  double flux_before = 0;
  for (Eigen::Index i = 0; i < v.rows(); ++i) flux_before += a.row(i).dot(v.row(i));
  ASSERT_GT(std::abs(flux_before), 1e-2);  // the test starts from a real flux
  const Points v0 = v;
  remove_normal_flux(a, v);
  double flux = 0, scale = 0;
  for (Eigen::Index i = 0; i < v.rows(); ++i) flux += a.row(i).dot(v.row(i)), scale += a.row(i).norm() * v.row(i).norm();
  EXPECT_LT(std::abs(flux), 1e-14 * scale);  // zero up to the round-off of the sums
  // The change is −c a_i/|a_i| with one c for all nodes.
  const double c = -(v - v0).row(0).dot(a.row(0).normalized());
  for (Eigen::Index i = 0; i < v.rows(); ++i)
    EXPECT_LT(((v - v0).row(i) + c * a.row(i).normalized()).norm(), 1e-14) << i;  // round-off of c·n
}

TEST(VolumeConstraint, ProjectionReachesTheTargetVolume) {
  SurfaceMesh m = bumpy_sphere();
  const double target = enclosed_volume(m);
  Points scratch;
  // At the target already: nothing moves, bit for bit.
  const Points x0 = m.vertices;
  EXPECT_EQ(project_volume(m.vertices, m.triangles, target, scratch), 0.0);
  EXPECT_EQ(m.vertices, x0);
  // 3 % too large (an inflated step): back to the target within the documented 1e-14 relative.
  m.vertices *= std::cbrt(1.03);
  const double moved = project_volume(m.vertices, m.triangles, target, scratch);
  EXPECT_LE(std::abs(enclosed_volume(m) - target), 1e-14 * target);
  // A uniform normal displacement δ changes V by about δ·area: |δ| ≈ 0.03 V / A (within 10 %,
  // the difference between vertex normals and the facets' and the 1 % of radius change).
  const double expected = 0.03 / 1.03 * target / surface_area(SurfaceMesh{x0, m.triangles});
  EXPECT_NEAR(moved, expected, 0.1 * expected);
}
