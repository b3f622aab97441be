// ChannelDynamics (rhs/channel_dynamics.hpp): a capsule in a tube's Poiseuille flow, in the frame
// that moves with its centroid.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "capsflow/core/bie/quadrature.hpp"
#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/rhs/channel_dynamics.hpp"
#include "capsflow/core/theory/poiseuille.hpp"

namespace capsflow {
namespace {

Scene sphere_scene(std::vector<std::string> more = {}) {
  std::vector<std::string> o = {"mesh.level=2", "mesh.shape=\"sphere\"", "wall.model=\"membrane\"", "wall.law=\"skalak\"",
                                "flow.ca_s=0.05"};
  o.insert(o.end(), more.begin(), more.end());
  return parse_scene(default_scene_toml(), "test", o);
}

ChannelFlow tube(double R) {
  ChannelFlow c;
  c.geometry.radius = R, c.geometry.length = 4 * R, c.geometry.element_size = R / 5;
  return c;
}

// A capsule at its reference shape carries no load, so nothing disturbs the flow: the wall's
// traction stays zero (no GMRES iteration) and every node moves with Poiseuille's flow less the
// centroid's axial velocity U — which is that flow's mean over the capsule's volume (dc/dt =
// ∫ x (u·n) dS / V = ∫ u dV / V for a divergence-free u), here for a sphere of radius a on the
// axis 2V(1 − 2a²/(5R²)) (the volume average of y² + z² over a sphere is 2a²/5): to the
// polyhedron's O(h²) (level 2: 0.5 % relative, bound 1 %).
TEST(ChannelDynamics, AnUnloadedCapsuleMovesWithThePoiseuilleFlowAndLeavesTheWallAtRest) {
  const Scene s = sphere_scene();
  const SurfaceMesh ref = make_reference_mesh(s.mesh);
  const double R = 2;
  ChannelDynamics d(s, ref, tube(R));
  Points v;
  d.evaluate(ref.vertices, v, {EvaluationHint::Role::Trajectory, 0});
  EXPECT_EQ(d.last_wall_solve().iterations, 0) << "the reference shape's load is round-off";
  EXPECT_EQ(d.channel_wall().traction().norm(), 0.0);
  const double U = d.axial_velocity();
  EXPECT_NEAR(U / (2 * (1 - 2.0 / (5 * R * R))), 1, 1e-2);
  double worst = 0;
  for (Eigen::Index i = 0; i < ref.num_nodes(); ++i) {
    const Vec3 x = ref.vertices.row(i).transpose();
    const Vec3 expected(tube_poiseuille_velocity(std::hypot(x.y(), x.z()), R, 1.0) - U, 0, 0);
    worst = std::max(worst, (v.row(i).transpose() - expected).norm());
  }
  // The volume correction moves the nodes by the P1 flux error only (a uniform flow through a
  // closed polyhedron has none; Poiseuille's curvature over 162 nodes: below 1e-3).
  EXPECT_LT(worst, 1e-3);
  // In the moving frame the centroid stands still along the channel.
  EXPECT_NEAR(centroid_rate(ref.vertices, ref.triangles, v).x(), 0, 1e-12);
}

// In a constricted duct the frame is the lab's: the centroid moves at U (not held still), and an
// unloaded capsule far upstream of the constriction moves, to within its disturbance, with the
// inlet duct's Poiseuille flow (its wall's velocity −u_P on the constriction is not felt there).
TEST(ChannelDynamics, InAConstrictionTheFrameIsTheLabsAndTheCapsuleAdvances) {
  const Scene s = sphere_scene({"mesh.level=1"});
  const SurfaceMesh ref = make_reference_mesh(s.mesh);
  ChannelFlow c;
  c.geometry.shape = ChannelShape::ConstrictedDuct;
  c.geometry.radius = 2, c.geometry.length = 20, c.geometry.element_size = 0.5;
  c.geometry.constriction_height = 1, c.geometry.constriction_width = 2, c.geometry.constriction_length = 2;
  c.geometry.constriction_center = 5, c.geometry.constriction_taper = 0.5;
  ChannelDynamics d(s, ref, c);
  Points v;
  d.evaluate(ref.vertices, v, {EvaluationHint::Role::Trajectory, 0});
  const double U = d.axial_velocity();
  EXPECT_NEAR(centroid_rate(ref.vertices, ref.triangles, v).x(), U, 1e-12);  // the lab frame: no −U e_x
  // The inlet duct's flow averaged over the sphere (of radius 1 in a duct of half-width 2, 3.5 from
  // the narrow part's taper): 2 % covers the level-1 polyhedron and the constriction's far field.
  double mean = 0, volume = 0;
  const GaussLegendre rule(8);
  for (int a = 0; a < 8; ++a)
    for (int b = 0; b < 8; ++b)
      for (int k = 0; k < 8; ++k) {
        const Vec3 p(2 * rule.x[a] - 1, 2 * rule.x[b] - 1, 2 * rule.x[k] - 1);
        if (p.norm() > 1) continue;
        const double w = rule.w[a] * rule.w[b] * rule.w[k];
        mean += w * duct_poiseuille_velocity(p.y(), p.z(), 2, 1.0), volume += w;
      }
  EXPECT_NEAR(U / (mean / volume), 1, 0.02);
  EXPECT_GT(d.channel_wall().traction().norm(), 0);  // the empty constriction's own traction
  // The outlet cap is at x1 = 10: the run stops once the front passes 10 − 1.25 × 2 = 7.5.
  const double front = ref.vertices.col(0).maxCoeff();
  Points moved = ref.vertices;
  EXPECT_FALSE(d.reached_outlet(moved));
  moved.col(0).array() += 7.5 - front - 0.01;
  EXPECT_FALSE(d.reached_outlet(moved));
  moved.col(0).array() += 0.02;
  EXPECT_TRUE(d.reached_outlet(moved));
  EXPECT_LT(std::abs(d.pressure_drop()), 1e-12);  // no load but round-off: nothing in the reciprocal theorem
  // A pre-inflated capsule's Laplace load is a pressure: it disturbs nothing outside and adds no
  // pressure drop (discretely: 1e-3 of the load's scale q·a² / R² = 0.7/4, against O(1) for a
  // reciprocal theorem taken with the wrong undisturbed flow).
  const Scene inflated = sphere_scene({"mesh.level=1", "wall.prestress=0.05", "flow.ca_s=1"});
  ChannelDynamics p(inflated, ref, c);
  p.evaluate(ref.vertices, v, {EvaluationHint::Role::Trajectory, 0});
  EXPECT_LT(std::abs(p.pressure_drop()), 1e-3 * 0.7 / 4);
}

// A loaded capsule disturbs the flow and the wall
// cancels that disturbance on itself: its traction is then nonzero, from a converged solve.
TEST(ChannelDynamics, TheWallAnswersALoadedCapsule) {
  const Scene s = sphere_scene();
  const SurfaceMesh ref = make_reference_mesh(s.mesh);
  ChannelDynamics d(s, ref, tube(1.6));
  // Bent into a bullet (its rim pulled back): no fore-aft symmetry, so its load does work against
  // Poiseuille's flow (a fore-aft symmetric load would add no pressure drop).
  Points x = ref.vertices;
  for (Eigen::Index i = 0; i < x.rows(); ++i) x(i, 0) -= 0.15 * (x(i, 1) * x(i, 1) + x(i, 2) * x(i, 2));
  Points v;
  d.evaluate(x, v, {EvaluationHint::Role::Trajectory, 0});
  EXPECT_TRUE(d.last_wall_solve().converged);
  EXPECT_GT(d.last_wall_solve().iterations, 0);
  EXPECT_GT(d.channel_wall().traction().norm(), 0);
  EXPECT_GT(d.wall_gap(), 1) << "the capsule is more than a wall element from the wall";
  EXPECT_NEAR(centroid_rate(x, ref.triangles, v).x(), 0, 1e-12) << "the frame moves with the centroid";
  // Its added pressure drop two ways: the reciprocal theorem on the capsule's load, and the caps'
  // pressure from the wall's solve. The rigid sphere of docs/channel.md §3.4 had them 3–7 % apart
  // on meshes like these (the caps' O(h)); measured here 7 %: bound 15 %, and the sign must agree.
  const double dp = d.pressure_drop(), caps = d.pressure_drop_from_caps();
  std::printf("pressure drop: reciprocal %.5f, caps %.5f\n", dp, caps);
  EXPECT_NE(dp, 0);
  EXPECT_NEAR(caps / dp, 1, 0.15);
}

// The same in a square duct: U is the duct flow's mean over the sphere's volume, here by a Gauss
// rule in spherical coordinates (12 × 12 × 24 points on the series solution): to the polyhedron's
// O(h²) (level 2: measured 0.82 %, bound 1.5 %).
TEST(ChannelDynamics, AnUnloadedCapsuleInASquareDuctMovesAtTheDuctFlowsVolumeMean) {
  const Scene s = sphere_scene();
  const SurfaceMesh ref = make_reference_mesh(s.mesh);
  ChannelFlow duct = tube(1.5);
  duct.geometry.shape = ChannelShape::SquareDuct;
  ChannelDynamics d(s, ref, duct);
  Points v;
  d.evaluate(ref.vertices, v, {EvaluationHint::Role::Trajectory, 0});
  EXPECT_EQ(d.last_wall_solve().iterations, 0);
  const GaussLegendre gr(12), gt(12);
  double mean = 0;
  const int na = 24;
  for (std::size_t i = 0; i < gr.x.size(); ++i)
    for (std::size_t j = 0; j < gt.x.size(); ++j)
      for (int k = 0; k < na; ++k) {
        const double r = gr.x[i], c = 2 * gt.x[j] - 1, a = 2 * M_PI * (k + 0.5) / na, sn = std::sqrt(1 - c * c);
        // dV = r² dr d(cos θ) dφ over the volume 4π/3
        mean += gr.w[i] * 2 * gt.w[j] * (2 * M_PI / na) * r * r *
                duct_poiseuille_velocity(r * sn * std::cos(a), r * sn * std::sin(a), 1.5, 1.0);
      }
  mean /= 4 * M_PI / 3;
  std::printf("duct: U %.6f, volume mean %.6f\n", d.axial_velocity(), mean);
  EXPECT_NEAR(d.axial_velocity() / mean, 1, 1.5e-2);
}

TEST(ChannelDynamics, RefusesAViscosityRatioOtherThanOne) {
  const Scene s = sphere_scene({"fluid.viscosity_ratio=2"});
  EXPECT_THROW(ChannelDynamics(s, make_reference_mesh(s.mesh), tube(2)), std::invalid_argument);
}

}  // namespace
}  // namespace capsflow
