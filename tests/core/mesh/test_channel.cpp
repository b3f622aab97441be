// The channel's closed surface (mesh/channel.hpp): closed, oriented outward, the exact shape's
// area and volume to the faceting error, element sizes as asked.
#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/mesh/channel.hpp"
#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/mesh/topology.hpp"

namespace capsflow {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(ChannelMesh, TubeAndDuctAreClosedOutwardAndOfTheirShapesVolume) {
  for (const ChannelShape shape : {ChannelShape::Tube, ChannelShape::SquareDuct}) {
    ChannelGeometry g;
    g.shape = shape, g.radius = 1.2, g.length = 6, g.element_size = 0.15;
    const ChannelMesh c = make_channel_mesh(g);
    SCOPED_TRACE(to_string(shape));
    SurfaceMesh copy = c.mesh;
    EXPECT_FALSE(validate_closed_surface(copy));  // closed, manifold, one sphere-like component, not flipped
    // Outward: the divergence theorem's volume is positive and equals the prism's. The tube's
    // polygon of n sides (n = 50 here) holds (n/2π) sin(2π/n) of the circle's area: the check is
    // to 1e-12 against that, and the area of the flat caps likewise.
    const double A = channel_cross_section_area(g);
    int sides = 0;
    for (const auto r : c.node_region) sides += r == ChannelRegion::Side;
    const int ring = shape == ChannelShape::Tube ? static_cast<int>(std::lround(2 * kPi * 1.2 / 0.15)) : 4 * 16;
    const double polygon = shape == ChannelShape::Tube ? ring / (2 * kPi) * std::sin(2 * kPi / ring) : 1.0;
    EXPECT_NEAR(enclosed_volume(c.mesh), polygon * A * g.length, 1e-12 * A * g.length);
    EXPECT_EQ(sides % ring, 0);  // the side is whole rings
    // Every element of the side has its normal pointing away from the axis, every cap element along ∓x.
    const Points nrm = element_normals(c.mesh);
    for (Eigen::Index e = 0; e < c.mesh.num_elements(); ++e) {
      Vec3 centroid = Vec3::Zero();
      for (int k = 0; k < 3; ++k) centroid += c.mesh.vertices.row(c.mesh.triangles(e, k)).transpose() / 3;
      const Vec3 away = std::abs(std::abs(centroid.x()) - 3) < 1e-12 ? Vec3(centroid.x(), 0, 0) : Vec3(0, centroid.y(), centroid.z());
      ASSERT_GT(nrm.row(e).dot(away.transpose()), 0) << "element " << e;
    }
    // Element sizes as asked and no sliver: every edge within [0.9, 1.8] of the target, every
    // angle at least 29° (the tube's caps zip rings of unequal counts, which makes 30-30-120°
    // triangles where two rings' nodes line up: the longest edge √3 h; the duct's diagonals are √2 h).
    const MeshStats st = mesh_stats(c.mesh);
    EXPECT_GT(st.edge_min, 0.9 * 0.15);
    EXPECT_LT(st.edge_max, 1.8 * 0.15);
    EXPECT_GT(st.min_angle_deg, 29.0);
  }
}

TEST(ChannelMesh, NodeRegionsMarkTheCapsInteriorsOnly) {
  ChannelGeometry g;
  g.radius = 1, g.length = 4, g.element_size = 0.2;
  const ChannelMesh c = make_channel_mesh(g);
  for (Eigen::Index i = 0; i < c.mesh.num_nodes(); ++i) {
    const Vec3 p = c.mesh.vertices.row(i).transpose();
    const double r = std::hypot(p.y(), p.z());
    const ChannelRegion expected = std::abs(r - 1) < 1e-12 ? ChannelRegion::Side
                                   : p.x() < 0            ? ChannelRegion::Inlet
                                                          : ChannelRegion::Outlet;
    ASSERT_EQ(c.node_region[static_cast<std::size_t>(i)], expected) << "node " << i;
  }
}

TEST(ChannelMesh, RefusesANonPositiveSizeOrAnElementLargerThanTheRadius) {
  ChannelGeometry g;
  g.radius = 0;
  EXPECT_THROW(make_channel_mesh(g), std::invalid_argument);
  g.radius = 1, g.length = -1;
  EXPECT_THROW(make_channel_mesh(g), std::invalid_argument);
  g.length = 4, g.element_size = 1.5;
  EXPECT_THROW(make_channel_mesh(g), std::invalid_argument);
}

TEST(ChannelMesh, ConstrictedDuctIsClosedOutwardAndExactlyItsShape) {
  // The tapers are planar (each half-size linear in x), so the polyhedron is the exact shape and
  // its volume the integral of the cross-section 4 h_y h_z: to round-off.
  ChannelGeometry g;
  g.shape = ChannelShape::ConstrictedDuct, g.radius = 1, g.length = 8, g.element_size = 0.2;
  g.constriction_height = 0.5, g.constriction_width = 0.7, g.constriction_length = 1.2, g.constriction_center = 0.4;
  g.constriction_taper = 0.3;
  const ChannelMesh c = make_channel_mesh(g);
  SurfaceMesh copy = c.mesh;
  EXPECT_FALSE(validate_closed_surface(copy));
  const double W = 1, H = 0.5, Z = 0.7, T = 0.3, L = 1.2;
  const double taper = T * (W * W + W * (H - W) / 2 + W * (Z - W) / 2 + (H - W) * (Z - W) / 3);
  const double exact = 4 * (W * W * (g.length - L - 2 * T) + H * Z * L + 2 * taper);
  EXPECT_NEAR(enclosed_volume(c.mesh), exact, 1e-12 * exact);
  // Every side node on the wall of its station, the narrow part's and the tapers' included.
  for (Eigen::Index i = 0; i < c.mesh.num_nodes(); ++i) {
    if (c.node_region[static_cast<std::size_t>(i)] != ChannelRegion::Side) continue;
    ASSERT_NEAR(relative_distance_from_axis(g, c.mesh.vertices.row(i).transpose()), 1.0, 1e-12) << "node " << i;
  }
  EXPECT_EQ(channel_half_sizes(g, 0.4), Eigen::Vector2d(0.5, 0.7));  // exact: the narrow part
  EXPECT_EQ(channel_half_sizes(g, -3.0), Eigen::Vector2d(1, 1));    // exact: the inlet's duct
  // No sliver where the wall turns inward: the tapers are cut by their slant, so edges stay within
  // [0.4, 1.8] of the target (the narrow part's ring is the wide one scaled by 0.5) and angles ≥ 20°.
  const MeshStats st = mesh_stats(c.mesh);
  EXPECT_GT(st.edge_min, 0.4 * 0.2);
  EXPECT_LT(st.edge_max, 1.8 * 0.2);
  EXPECT_GT(st.min_angle_deg, 20.0);
}

TEST(ChannelMesh, RefusesAConstrictionThatDoesNotFit) {
  ChannelGeometry g;
  g.shape = ChannelShape::ConstrictedDuct, g.radius = 1, g.length = 6, g.element_size = 0.2;
  g.constriction_height = 1.2;  // wider than the duct
  EXPECT_THROW(make_channel_mesh(g), std::invalid_argument);
  g.constriction_height = 0.5, g.constriction_center = 2.8;  // reaches the outlet cap
  EXPECT_THROW(make_channel_mesh(g), std::invalid_argument);
  g.constriction_center = 0, g.constriction_taper = 0;  // a vertical step: the mesh cannot make it
  EXPECT_THROW(make_channel_mesh(g), std::invalid_argument);
}

}  // namespace
}  // namespace capsflow
