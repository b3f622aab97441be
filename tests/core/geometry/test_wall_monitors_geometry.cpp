// The geometric health monitors: umbrella operator, facet angles, grid-scale oscillation, element
// quality and principal stretches, each against a case whose answer is known in closed form or
// by construction.
#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/geometry/element_quality.hpp"
#include "capsflow/core/geometry/surface_roughness.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/geometry/umbrella.hpp"

using namespace capsflow;

namespace {
SurfaceMesh ico(int level) { return make_sphere_mesh(BaseSolid::Icosahedron, level); }
Points vertex_normals_of_sphere(const Points& x) { return x.rowwise().normalized(); }
}  // namespace

TEST(Umbrella, ConstantFieldIsInItsKernelAndPatternIsGridScale) {
  const SurfaceMesh m = ico(3);
  const UmbrellaOperator u(m.triangles, m.num_nodes());
  Points c = Points::Ones(m.num_nodes(), 3), out;
  u.apply(c, out);
  EXPECT_LT(out.cwiseAbs().maxCoeff(), 1e-14);  // mean of equal values minus the value: round-off only
  // The pattern is dominated by the largest-magnitude eigenvalues of U (the graph Laplacian's top
  // is ≈ −1.5 on a triangulation of valence 6): |U p| / |p| near that, far above the smooth modes
  // (the coordinate field x, a degree-1 harmonic, gives ≈ h²/2 ≈ 0.01 at level 3).
  const Points p = grid_scale_pattern(u);
  u.apply(p, out);
  EXPECT_GT(out.norm() / p.norm(), 1.2);  // grid-scale: ≥ 80 % of the top of the spectrum
  u.apply(m.vertices, out);
  EXPECT_LT(out.norm() / m.vertices.norm(), 0.02);  // smooth: O(h²)
}

TEST(PrincipalStretches, RecoverAnAffineMapInAnyOrientation) {
  const Vec3 A(0, 0, 0), B(1, 0.2, 0), C(0.3, 1, 0);
  // Stretch by 2 along x and 0.5 along y, then rotate arbitrarily in 3-D.
  const Eigen::Matrix3d S = Eigen::Vector3d(2.0, 0.5, 1.0).asDiagonal();
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const PrincipalStretches p = principal_stretches(A, B, C, R * S * A, R * S * B, R * S * C);
  EXPECT_NEAR(p.l1, 2.0, 1e-12);  // exact up to round-off
  EXPECT_NEAR(p.l2, 0.5, 1e-12);
}

TEST(ElementQuality, EquilateralUndeformedAndDistortedFacets) {
  SurfaceMesh one;
  one.vertices.resize(3, 3);
  one.vertices << 0, 0, 0, 1, 0, 0, 0.5, std::sqrt(3.0) / 2, 0;
  one.triangles.resize(1, 3);
  one.triangles << 0, 1, 2;
  ElementQuality q = element_quality(one, one.vertices);
  EXPECT_NEAR(q.min_angle_deg, 60.0, 1e-9);  // equilateral: all angles 60°
  EXPECT_NEAR(q.max_aspect_ratio, 1.0, 1e-12);
  EXPECT_NEAR(q.max_stretch_ratio, 1.0, 1e-12);
  // Squash along y by 4: angles atan(0.866/4 / 0.5) = 23.4° at the base; λ = (1, 1/4).
  Points x = one.vertices;
  x.col(1) /= 4;
  q = element_quality(one, x);
  EXPECT_NEAR(q.min_angle_deg, std::atan((std::sqrt(3.0) / 8) / 0.5) * 180 / M_PI, 1e-9);
  EXPECT_NEAR(q.max_stretch_ratio, 4.0, 1e-12);
  EXPECT_NEAR(q.min_stretch, 0.25, 1e-12);
  EXPECT_GT(q.max_aspect_ratio, 2.0);  // a flattened facet (exact value ≈ 2.6)
}

TEST(SurfaceRoughness, SmoothSphereResolvedWrinklesAndGridScaleNoiseAreTold) {
  const SurfaceMesh m = ico(4);  // 5120 facets, h ≈ 0.05
  const RoughnessMeter meter(m.triangles, m.num_nodes());
  const SurfaceRoughness smooth = meter.measure(m.vertices);
  // Adjacent facet normals of a unit-sphere icosphere differ by ≈ h/R: 2.9–4° at level 4.
  EXPECT_LT(smooth.facet_angle_max, 5.0);
  EXPECT_LT(smooth.grid_oscillation_p99, 0.005);  // only the irregular 5-valent nodes (≈ 0.0025)

  // A fold pattern resolved by ≈ 8 elements per wavelength (r = 1 + 0.03 cos 8φ sin²θ, wavelength
  // 2π/8 ≈ 0.8 ≈ 16 h at the equator): the facets turn by tens of degrees less than mesh-scale
  // buckling would, and the grid-scale indicator must stay near the smooth sphere's.
  Points fold = m.vertices;
  for (Eigen::Index i = 0; i < fold.rows(); ++i) {
    const Vec3 p = fold.row(i);
    const double phi = std::atan2(p.y(), p.x()), s2 = 1 - p.z() * p.z();
    fold.row(i) *= 1 + 0.03 * std::cos(8 * phi) * s2;
  }
  const SurfaceRoughness folded = meter.measure(fold);
  EXPECT_GT(folded.facet_angle_max, smooth.facet_angle_max + 1.0);  // the fold bends the facets
  EXPECT_LT(folded.grid_oscillation_p99, 0.03);  // not grid-scale: below the buckling threshold 0.03 (docs/health-monitors.md)

  // Grid-scale noise: each node moved along the normal by ±5 % of h, signs pseudo-random.
  Points noisy = m.vertices;
  const Points n = vertex_normals_of_sphere(m.vertices);
  unsigned state = 12345;
  for (Eigen::Index i = 0; i < noisy.rows(); ++i) {
    state = state * 1103515245u + 12345u;
    noisy.row(i) += ((state >> 16) & 1 ? 1.0 : -1.0) * 0.05 * 0.05 * n.row(i);
  }
  const SurfaceRoughness rough = meter.measure(noisy);
  // |U c|/h for ±a h noise is of order 2a (U roughly doubles an alternating field, twice over,
  // minus cancellations of random signs): must exceed the buckling threshold 0.03.
  EXPECT_GT(rough.grid_oscillation_p99, 0.03);
}
