// The fixed wall's first-kind solve (bie/fixed_wall.hpp) on closed channels, against exact
// solutions (channel_cases.hpp; the full convergence tables: perf/bie/channel_wall, docs/channel.md §3.3).
#include <gtest/gtest.h>

#include <cmath>

#include "channel_cases.hpp"

namespace capsflow {
namespace {

using channel_cases::CaseResult;

// Flat P1 elements carry the faceting error, O(h²): measured 1.3e-2 / 4.8e-3 (tube) and 1.4e-2 /
// 6.2e-3 (duct) at h = 0.3 / 0.2. The bounds are 1.5× those, and the order between the two at
// least 1.5 (measured 2.4 and 2.0): a first-order error (a wrong jump, a lost term) fails both.
TEST(FixedWall, TheFlowOfAnOutsidePointForceIsRecoveredInside) {
  for (const ChannelShape shape : {ChannelShape::Tube, ChannelShape::SquareDuct}) {
    SCOPED_TRACE(to_string(shape));
    const CaseResult coarse = channel_cases::outside_point_force(shape, 0.3);
    const CaseResult fine = channel_cases::outside_point_force(shape, 0.2);
    EXPECT_TRUE(coarse.converged && fine.converged);
    EXPECT_LT(coarse.error, 2.1e-2);
    EXPECT_LT(fine.error, 9.2e-3);
    EXPECT_GT(std::log(coarse.error / fine.error) / std::log(1.5), 1.5);
  }
}

// The reciprocal theorem's pressure drop p_in − p_out = −F·u_P(x_s)/Q, read from the caps'
// traction: measured 0.51 % / 0.23 % (tube) and 0.23 % / 0.10 % (duct) off at h = 0.3 / 0.2 with
// the traction's pressure carried by each face's normal at the edges (docs/channel.md §3.5; the
// plain P1 traction is 13.6 % / 5.6 % and 14.6 % / 8.0 % off: the caps' pressure meets the rims).
// Bounds 1.3× the measured errors; the sign and size of the drop are wrong by 100 % if a jump or a
// sign is.
TEST(FixedWall, APointForceInsideAddsTheReciprocalTheoremsPressureDrop) {
  for (const ChannelShape shape : {ChannelShape::Tube, ChannelShape::SquareDuct}) {
    SCOPED_TRACE(to_string(shape));
    const CaseResult coarse = channel_cases::inside_point_force(shape, 0.3);
    const CaseResult fine = channel_cases::inside_point_force(shape, 0.2);
    EXPECT_TRUE(coarse.converged && fine.converged);
    EXPECT_LT(coarse.error, shape == ChannelShape::Tube ? 6.7e-3 : 3.0e-3);
    EXPECT_LT(fine.error, shape == ChannelShape::Tube ? 3.0e-3 : 1.35e-3);
    EXPECT_LT(fine.error, coarse.error);
  }
}

// A wall at rest with nothing inducing a flow has no traction: the solve returns zero at once.
TEST(FixedWall, AWallAtRestWithoutForcingHasNoTraction) {
  ChannelGeometry g;
  g.length = 3, g.element_size = 0.4;
  const ChannelMesh c = make_channel_mesh(g);
  FixedWall wall(c.mesh, Points::Zero(c.mesh.num_nodes(), 3));
  const FixedWallSolve s = wall.solve();
  EXPECT_TRUE(s.converged);
  EXPECT_EQ(s.iterations, 0);
  EXPECT_EQ(wall.traction().norm(), 0.0);
}

TEST(FixedWall, RefusesAVelocityOfTheWrongSizeAndCurvedElements) {
  ChannelGeometry g;
  g.length = 3, g.element_size = 0.4;
  const ChannelMesh c = make_channel_mesh(g);
  EXPECT_THROW(FixedWall(c.mesh, Points::Zero(3, 3)), std::invalid_argument);
  FixedWallOptions o;
  o.layer.geometry = SurfaceGeometry::Curved;
  EXPECT_THROW(FixedWall(c.mesh, Points::Zero(c.mesh.num_nodes(), 3), o), std::invalid_argument);
}


// A free rigid sphere on a tube's axis (a sphere of 162 nodes, the wall at R/8): U/V against the
// published results (channel_cases.hpp). At a/R = 0.3 Haberman & Sayre's reflection result and
// Bungay & Brenner's fit agree to 0.13 %, and this mesh is 0.10 % above the fit (0.06 % with 642
// nodes, perf/bie/channel_wall): bound 0.25 % from each. At a/R = 0.7 only the fit holds (the
// reflection result is 3.5 % off there); measured +0.08 % at this mesh: bound 0.3 %. The two
// estimates of the added pressure drop — the caps' traction and the reciprocal theorem on the
// sphere — measured 7 % apart at 162 nodes (3 % at 642): bound 10 %.
TEST(FixedWall, AFreeRigidSphereOnATubesAxisMovesAtThePublishedVelocity) {
  {
    const channel_cases::SphereResult r = channel_cases::free_sphere_on_axis(0.3, 2);
    EXPECT_TRUE(r.converged);
    EXPECT_NEAR(r.velocity_ratio / channel_cases::bungay_brenner_velocity(0.3), 1, 2.5e-3);
    EXPECT_NEAR(r.velocity_ratio / channel_cases::haberman_sayre_velocity(0.3), 1, 2.5e-3);
  }
  const channel_cases::SphereResult r = channel_cases::free_sphere_on_axis(0.7, 2);
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(r.velocity_ratio / channel_cases::bungay_brenner_velocity(0.7), 1, 3e-3);
  EXPECT_GT(r.pressure_drop_reciprocal, 0);
  EXPECT_NEAR(r.pressure_drop_caps / r.pressure_drop_reciprocal, 1, 0.10);
}

}  // namespace
}  // namespace capsflow
