// The fixed wall's first-kind solve (bie/fixed_wall.hpp) on closed channels, against exact
// solutions (channel_cases.hpp; the full convergence tables: perf/bie/channel_wall, docs/channel.md §3.3).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include <fmt/core.h>

#include "capsflow/core/bie/fixed_single_layer.hpp"
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

// The wall's operator set up once (fixed_single_layer.hpp) against SingleLayer::apply, which
// recomputes everything, on a tube (length 3, elements 0.3: 275 nodes) with a random load, by the
// direct sum and by the FMM (forced; at this size "auto" sums directly), and a second load after
// the first (the FMM's tree and the near-field matrix reused). Both sum the same terms — the same
// sources, quadrature points and back end — in another order (the near field by a matrix instead
// of rule by rule), so they agree to round-off: measured ≤ 1.8e-15 of max |S[q]| with the direct
// sum and the FMM alike (the FMM being deterministic on the same points). Bound 1e-12 of
// max |S[q]|, far below the far field's tolerance (1e-6): one band point of one element put at
// the wrong place measured 3e-2. The dense matrix sums the far-field pairs in full precision,
// where the direct sum's pairs may err by up to 6e-9 each (AVX-512 builds: one Newton step after
// the hardware rsqrt, far_field.hpp; this AVX2 build measured 2.1e-15): bound 1e-8.
TEST(FixedWall, TheOperatorSetUpOnceEqualsTheSingleLayer) {
  ChannelGeometry g;
  g.length = 3, g.element_size = 0.3;
  const ChannelMesh c = make_channel_mesh(g);
  const Eigen::Index n = c.mesh.num_nodes();
  struct Case {
    BackendRequest backend;
    double dense_megabytes, bound;
  };
  for (const Case k : {Case{BackendRequest::Direct, 0, 1e-12}, Case{BackendRequest::Fmm, 0, 1e-12},
                       Case{BackendRequest::Direct, 1000, 1e-8}}) {
    SCOPED_TRACE(fmt::format("{}, dense budget {} MB", to_string(k.backend), k.dense_megabytes));
    SingleLayerOptions o;
    o.backend = k.backend;
    FixedSingleLayer fixed(c.mesh, o, k.dense_megabytes);
    SingleLayer S(c.mesh.triangles, n, o);
    EXPECT_EQ(fixed.backend(), k.backend == BackendRequest::Fmm ? FarFieldBackend::Fmm : FarFieldBackend::Direct);
    EXPECT_EQ(fixed.dense(), k.dense_megabytes > 0);
    std::srand(7);
    for (int repeat = 0; repeat < 2; ++repeat) {
      const Points q = Points::Random(n, 3);
      Points u_fixed, u;
      fixed.apply(q, u_fixed);
      S.apply(c.mesh.vertices, q, u);
      const double scale = u.rowwise().norm().maxCoeff();
      EXPECT_GT(scale, 0);
      EXPECT_LT((u_fixed - u).rowwise().norm().maxCoeff() / scale, k.bound);
    }
  }
}

// The wall's solve with the operator set up once and with SingleLayer recomputed at every
// iteration: the same operator to round-off, so GMRES takes the same iterates: the same count
// (24) and the same traction, measured 5e-15 (sparse near field) and 7e-15 (dense) of its largest
// value apart. Bound 1e-10: round-off
// grown by the first-kind equation's conditioning (~1/h) stays far below it, and the misplaced
// band point above measured 2e-2.
TEST(FixedWall, TheSolveIsTheSameWithTheOperatorSetUpOnce) {
  ChannelGeometry g;
  g.length = 3, g.element_size = 0.4;
  const ChannelMesh c = make_channel_mesh(g);
  Points induced(c.mesh.num_nodes(), 3);
  for (Eigen::Index i = 0; i < induced.rows(); ++i)
    induced.row(i) = channel_cases::point_force_flow(c.mesh.vertices.row(i).transpose(), Vec3(0.2, 0.3, 0), Vec3(1, 0.5, 0)).transpose();
  FixedWallOptions o;
  o.reuse_operator = false;
  FixedWall recomputed(c.mesh, Points::Zero(c.mesh.num_nodes(), 3), o);
  EXPECT_EQ(recomputed.operator_megabytes(), 0);
  const FixedWallSolve b = recomputed.solve(&induced);
  const double scale = recomputed.traction().cwiseAbs().maxCoeff();
  EXPECT_GT(scale, 0);
  o.reuse_operator = true;
  for (const double dense_megabytes : {0.0, 1000.0}) {  // the sparse near field and direct far field; the dense matrix
    SCOPED_TRACE(dense_megabytes);
    o.dense_operator_mb = dense_megabytes;
    FixedWall reused(c.mesh, Points::Zero(c.mesh.num_nodes(), 3), o);
    EXPECT_EQ(reused.fixed_operator()->dense(), dense_megabytes > 0);
    EXPECT_GT(reused.operator_megabytes(), 0);
    const FixedWallSolve a = reused.solve(&induced);
    EXPECT_TRUE(a.converged && b.converged);
    EXPECT_EQ(a.iterations, b.iterations);
    EXPECT_LT((reused.traction() - recomputed.traction()).cwiseAbs().maxCoeff() / scale, 1e-10);
  }
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
