// Cross-section profiles of the sphere mesh lie on the unit circle within the chordal error.
#include <gtest/gtest.h>

#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/geometry/profiles.hpp"

using namespace capsflow;

TEST(Profiles, SphereSectionsOnUnitCircle) {
  const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 4);
  const double hmax = mesh_stats(m).edge_max;
  for (CoordinatePlane p : {CoordinatePlane::X1X2, CoordinatePlane::X1X3, CoordinatePlane::X2X3}) {
    const auto lines = cross_section(m, p, Vec3(0.01, 0.02, 0.015));  // off the symmetry planes
    ASSERT_EQ(lines.size(), 1u) << to_string(p);  // one closed loop through a convex surface
    EXPECT_TRUE(lines[0].closed);
    const int axis = p == CoordinatePlane::X1X2 ? 2 : (p == CoordinatePlane::X1X3 ? 1 : 0);
    const double off = axis == 0 ? 0.01 : (axis == 1 ? 0.02 : 0.015);
    const double R = std::sqrt(1 - off * off);
    double perimeter = 0;
    for (size_t i = 0; i < lines[0].points.size(); ++i) {
      const Vec3& x = lines[0].points[i];
      EXPECT_DOUBLE_EQ(x[axis], off);
      // Points lie on chords of the sphere: radius in [1 − h²/8·(1+margin), 1] (chordal sagitta h²/8R).
      const double r = std::sqrt(x.squaredNorm() - off * off);
      EXPECT_LE(r, R + 1e-12);
      EXPECT_GE(r, R - hmax * hmax / 8 * 1.01);
      if (i) perimeter += (x - lines[0].points[i - 1]).norm();
    }
    EXPECT_NEAR(perimeter, 2 * M_PI * R, 2 * M_PI * R * hmax * hmax / 4);  // inscribed polygon, O(h²)
  }
}

TEST(Profiles, VertexOnPlaneCountedOnce) {
  // Cutting exactly through vertices (x3 = 0 contains the icosphere's equatorial vertices of the
  // octahedron base) must still give one closed loop without duplicate points.
  const SurfaceMesh m = make_sphere_mesh(BaseSolid::Octahedron, 2);
  const auto lines = cross_section(m, CoordinatePlane::X1X2, Vec3::Zero());
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_TRUE(lines[0].closed);
  for (size_t i = 1; i < lines[0].points.size(); ++i)
    EXPECT_GT((lines[0].points[i] - lines[0].points[i - 1]).norm(), 1e-12) << "duplicate point " << i;
}
