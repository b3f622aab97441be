// The biconcave disc (mesh.shape = "biconcave", Evans & Fung 1972): vertices on the analytic surface,
// a closed outward mesh, and volume and area converging at second order in h to the shape's own —
// computed here by independent quadrature of the surface of revolution and checked against the
// closed-form volume and the published values (≈ 94 µm³, ≈ 135 µm² at R = 3.91 µm).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/mesh/biconcave.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/mesh/topology.hpp"
#include "capsflow/core/scene/scene.hpp"

using namespace capsflow;

namespace {

constexpr double kR = 3.91;                                    // µm, the disc radius of the coefficients
constexpr double kC0 = 0.2072, kC1 = 2.0026, kC2 = -1.1228;    // Evans & Fung (1972), typed again here

// Composite Simpson on [a, b] with n (even) intervals.
double simpson(const std::function<double(double)>& f, double a, double b, int n) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4.0 : 2.0) * f(a + i * h);
  return s * h / 3;
}

// The generating curve in the angle t ∈ [0, π/2]: r = R sin t, z = (R/2) cos t P(sin² t), smooth up
// to the rim (in r, z'(r) is infinite there).
struct Curve {
  static double P(double s) { return kC0 + kC1 * s + kC2 * s * s; }
  static double dP(double s) { return kC1 + 2 * kC2 * s; }
  static double r(double t) { return kR * std::sin(t); }
  static double z(double t) { return 0.5 * kR * std::cos(t) * P(std::sin(t) * std::sin(t)); }
  static double dr(double t) { return kR * std::cos(t); }
  static double dz(double t) {
    const double s = std::sin(t), c = std::cos(t);
    return 0.5 * kR * (-s * P(s * s) + c * dP(s * s) * 2 * s * c);
  }
};

// Both halves, by cylindrical shells: V = 2 ∫_0^R 2π r z(r) dr with r = R sin t; A = 2 ∫ 2π r ds.
double volume_by_quadrature(int n) {
  return simpson([](double t) { return 2 * 2 * M_PI * Curve::r(t) * Curve::z(t) * Curve::dr(t); }, 0, M_PI / 2, n);
}
double area_by_quadrature(int n) {
  return simpson([](double t) { return 2 * 2 * M_PI * Curve::r(t) * std::hypot(Curve::dr(t), Curve::dz(t)); }, 0,
                 M_PI / 2, n);
}

SurfaceMesh disc(int level, int axis = 2) {
  SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, level);
  map_to_biconcave(m, kR, axis);
  return m;
}

}  // namespace

TEST(Biconcave, QuadratureOraclesAgreeWithTheClosedFormVolumeAndThePublishedValues) {
  // V = 2π R³ ∫ sin t cos² t P(sin² t) dt = π R³ (2/3 C0 + 4/15 C1 + 16/105 C2) (u = sin² t, Beta integrals).
  const double v_closed = M_PI * kR * kR * kR * (2.0 / 3 * kC0 + 4.0 / 15 * kC1 + 16.0 / 105 * kC2);
  const double v = volume_by_quadrature(2000), a = area_by_quadrature(2000);
  // Simpson's error with 2000 intervals on a smooth integrand: ~h⁴ f'''' ~ 1e-12 relative.
  EXPECT_NEAR(v / v_closed, 1.0, 1e-10);
  EXPECT_NEAR(area_by_quadrature(4000) / a, 1.0, 1e-10);  // converged
  // Published for R = 3.91 µm: volume ≈ 94 µm³, area ≈ 135 µm² (given to 2–3 digits: ±1 %).
  EXPECT_NEAR(v, 94.0, 0.01 * 94.0);
  EXPECT_NEAR(a, 135.0, 0.01 * 135.0);
}

TEST(Biconcave, EveryVertexLiesOnTheDiscAndTheMeshIsClosedAndOutward) {
  for (int axis = 0; axis < 3; ++axis) {
    SurfaceMesh m = disc(3, axis);
    EXPECT_FALSE(validate_closed_surface(m));
    EXPECT_GT(enclosed_volume(m), 0);  // outward orientation kept
    double r_max = 0;
    for (Eigen::Index i = 0; i < m.num_nodes(); ++i) {
      Vec3 x = m.vertices.row(i).transpose();
      const double z = x(axis);
      x(axis) = 0;
      const double rho = x.norm() / kR;
      r_max = std::max(r_max, rho);
      ASSERT_LE(rho, 1 + 1e-14);
      // On the surface: (2z/(R P(ρ²)))² + ρ² = 1, the implicit form (z(r)'s sqrt would amplify the rim's
      // round-off to 1e-8); P ≥ C0 > 0. Round-off of a few operations on O(1) numbers.
      const double u = 2 * z / (kR * (kC0 + kC1 * rho * rho + kC2 * std::pow(rho, 4)));
      EXPECT_NEAR(u * u + rho * rho, 1.0, 1e-14) << "vertex " << i;
    }
    EXPECT_NEAR(r_max, 1.0, 1e-14);  // the icosphere's equatorial vertices land on the rim
  }
}

// Flat facets through points of a smooth surface: area and volume errors O(h²); from one level to the
// next h halves, so the error ratio tends to 4 (order 2). The observed order is checked in [1.8, 2.2]
// (the asymptotic range: on the sphere the same meshes give 1.98–2.00).
TEST(Biconcave, MeshVolumeAndAreaConvergeToTheShapesAtSecondOrder) {
  const double v = volume_by_quadrature(4000), a = area_by_quadrature(4000);
  double prev_ev = 0, prev_ea = 0;
  for (int level = 3; level <= 6; ++level) {
    const SurfaceMesh m = disc(level);
    const double ev = std::abs(v - enclosed_volume(m)), ea = std::abs(a - surface_area(m));
    std::printf("level %d: volume error %.3e, area error %.3e (relative %.2e, %.2e)\n", level, ev, ea, ev / v, ea / a);
    EXPECT_LT(ea / a, 0.02) << "level " << level;  // ≤ 2 % even at 1 280 elements
    if (level > 3) {
      EXPECT_NEAR(std::log2(prev_ev / ev), 2.0, 0.2) << "volume, levels " << level - 1 << "→" << level;
      EXPECT_NEAR(std::log2(prev_ea / ea), 2.0, 0.2) << "area, levels " << level - 1 << "→" << level;
    }
    prev_ev = ev;
    prev_ea = ea;
  }
}

TEST(Biconcave, SceneShapeGivesTheUnitEquivalentRadiusDiscWithUsableElements) {
  const Scene s = parse_scene("[mesh]\nshape = \"biconcave\"\nlevel = 3\n", "s.toml");
  EXPECT_EQ(s.mesh.shape, MeshShape::Biconcave);
  const SurfaceMesh m = make_reference_mesh(s.mesh);
  EXPECT_EQ(m.num_elements(), 1280);
  EXPECT_NEAR(enclosed_volume(m), 4 * M_PI / 3, 1e-12);  // ℓ = 1 (docs/conventions.md §4.2), round-off
  // R/ℓ of the smooth disc, ℓ = (3V/4π)^(1/3); at level 3 the polyhedron's volume is within ~1 % of V,
  // so its scale (∝ V^(-1/3)) within ~0.5 %.
  const double ell = std::cbrt(3 * volume_by_quadrature(4000) / (4 * M_PI));
  EXPECT_NEAR(m.vertices.col(0).cwiseAbs().maxCoeff(), kR / ell, 0.005 * kR / ell);
  EXPECT_NEAR(m.vertices.col(2).cwiseAbs().minCoeff(), 0.0, 1e-14);  // symmetry axis x3 by default: rim at x3 = 0
  // Element quality: the map flattens the icosphere's polar caps into the dimples and squeezes the
  // equator into the rim; angles stay within [20°, 120°] at 1 280 elements (the sphere: 54–72°).
  const MeshStats st = mesh_stats(m);
  std::printf("level 3 disc: angles %.1f–%.1f°, edges %.4f–%.4f\n", st.min_angle_deg, st.max_angle_deg, st.edge_min, st.edge_max);
  EXPECT_GT(st.min_angle_deg, 20.0);
  EXPECT_LT(st.max_angle_deg, 120.0);
}
