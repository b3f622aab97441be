// Subdivided icosahedron/octahedron meshes: counts, topology, convergence of area and volume.
#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/geometry/taylor_deformation.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/mesh/topology.hpp"

using namespace capsflow;

class MeshLevels : public ::testing::TestWithParam<std::tuple<BaseSolid, int>> {};

TEST_P(MeshLevels, CountsEulerClosedAndOutward) {
  const auto [base, level] = GetParam();
  SurfaceMesh m = make_sphere_mesh(base, level);
  const long f0 = base == BaseSolid::Icosahedron ? 20 : 8;
  const long F = f0 * (1L << (2 * level));
  // Exact integer identities: F = f0·4^k, E = 3F/2, V = E − F + 2 (sphere).
  EXPECT_EQ(m.num_elements(), F);
  EXPECT_EQ(mesh_edges(m).rows(), 3 * F / 2);
  EXPECT_EQ(m.num_nodes(), 3 * F / 2 - F + 2);
  EXPECT_EQ(m.num_nodes() - mesh_edges(m).rows() + m.num_elements(), 2);  // Euler characteristic
  const auto c = expected_counts(base, level);
  EXPECT_EQ(c.elements, F);
  EXPECT_EQ(c.nodes, m.num_nodes());
  // Closed, manifold, consistently oriented; already outward so nothing is flipped.
  EXPECT_FALSE(validate_closed_surface(m));
  for (Eigen::Index i = 0; i < m.num_nodes(); ++i)
    EXPECT_NEAR(m.vertices.row(i).norm(), 1.0, 1e-14) << "vertex " << i;  // projected on the unit sphere (round-off)
  const Points n = element_normals(m);
  for (Eigen::Index e = 0; e < m.num_elements(); ++e) {
    const Vec3 centroid = (m.vertices.row(m.triangles(e, 0)) + m.vertices.row(m.triangles(e, 1)) + m.vertices.row(m.triangles(e, 2))).transpose() / 3;
    EXPECT_GT(n.row(e).dot(centroid), 0) << "element " << e << " points inward";  // outward: n·x > 0 on a convex sphere mesh
  }
}

INSTANTIATE_TEST_SUITE_P(BothBasesLevels0to6, MeshLevels,
                         ::testing::Combine(::testing::Values(BaseSolid::Icosahedron, BaseSolid::Octahedron),
                                            ::testing::Range(0, 7)));

// Area and volume of the inscribed polyhedron converge to 4π and 4π/3 at second order in h.
TEST(SphereMesh, AreaAndVolumeConvergeAtSecondOrder) {
  for (BaseSolid base : {BaseSolid::Icosahedron, BaseSolid::Octahedron}) {
    double prev_a = 0, prev_v = 0;
    for (int level = 3; level <= 6; ++level) {
      const SurfaceMesh m = make_sphere_mesh(base, level);
      const double ea = std::abs(surface_area(m) - 4 * M_PI), ev = std::abs(enclosed_volume(m) - 4 * M_PI / 3);
      if (level > 3) {
        // Each level halves h, so the error ratio is 2^order; theory gives order 2 for chordal error.
        const double order_a = std::log2(prev_a / ea), order_v = std::log2(prev_v / ev);
        EXPECT_GE(order_a, 1.9) << to_string(base) << " level " << level;  // issue floor 1.9 (theory: 2)
        EXPECT_GE(order_v, 1.9) << to_string(base) << " level " << level;
      }
      prev_a = ea, prev_v = ev;
    }
  }
}

TEST(SpheroidMesh, UnitEquivalentRadiusAndExactTaylorDeformation) {
  for (BaseSolid base : {BaseSolid::Icosahedron, BaseSolid::Octahedron})
    for (int level : {2, 4}) {
      SurfaceMesh m = make_sphere_mesh(base, level);
      map_to_spheroid(m, 1.4, 2);
      // ℓ = 1 by construction of the volume scaling: round-off only.
      EXPECT_NEAR(equivalent_radius(enclosed_volume(m)), 1.0, 1e-14);
      // Affine image of a centrally symmetric polyhedron: the volume inertia ellipsoid has exactly
      // the aspect ratio 1.4 (docs/conventions.md §5.2), so D13 = D23 = (1 − 1.4)/(1 + 1.4) = −1/6, D12 = 0.
      const TaylorDeformation D = taylor_deformation(inertia_ellipsoid(m));
      EXPECT_NEAR(D.D13, -1.0 / 6.0, 1e-12);
      EXPECT_NEAR(D.D23, -1.0 / 6.0, 1e-12);
      EXPECT_NEAR(D.D12, 0.0, 1e-12);
    }
}

TEST(SpheroidMesh, AxisSelection) {
  SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 3);
  map_to_spheroid(m, 1.4, 0);  // long axis along x1
  const Vec3 L = half_extents(m);
  EXPECT_GT(L[0], 1.3 * L[1]);  // aspect 1.4 up to faceting (≥ 1.3 with margin)
  EXPECT_NEAR(L[1], L[2], 1e-2 * L[1]);  // transverse axes equal up to mesh asymmetry (< 1 %)
}

TEST(MeshGeneration, RejectsBadArguments) {
  EXPECT_THROW(make_sphere_mesh(BaseSolid::Icosahedron, -1), std::invalid_argument);
  EXPECT_THROW(make_sphere_mesh(BaseSolid::Icosahedron, 11), std::invalid_argument);
  EXPECT_FALSE(from_string<BaseSolid>("cube").has_value());  // not a base solid
  EXPECT_EQ(from_string<BaseSolid>("octahedron"), BaseSolid::Octahedron);
  SurfaceMesh m = make_sphere_mesh(BaseSolid::Octahedron, 1);
  EXPECT_THROW(map_to_spheroid(m, -1.0, 2), std::invalid_argument);
  EXPECT_THROW(map_to_spheroid(m, 1.4, 3), std::invalid_argument);
}
