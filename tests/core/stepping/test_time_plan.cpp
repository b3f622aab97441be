// The time plan (stepping/time_plan.hpp): every branch of the choice of scheme, tolerance and crease
// action; the stiffness it is made from; the tolerance in force along a crease history; the plan's
// round trip through a checkpoint; and when a restart keeps it. Expected values are the documented
// constants and formulas (auto_scheme.hpp, auto_tolerance.hpp), computed here independently.
#include "capsflow/core/stepping/time_plan.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "capsflow/core/stepping/auto_scheme.hpp"
#include "capsflow/core/stepping/stability.hpp"

using namespace capsflow;

namespace {

Scene scene_with(const std::vector<std::string>& sets) { return parse_scene(default_scene_toml(), "test", sets); }

TimePlan plan_for(const std::vector<std::string>& sets) {
  const Scene s = scene_with(sets);
  return resolve_time_plan(s, make_reference_mesh(s.mesh));
}

}  // namespace

TEST(AutoScheme, Rock4BelowTheThresholdAndRkc2FromIt) {
  EXPECT_EQ(auto_scheme(616.0), TimeScheme::Rock4);  // Table 1 at 5 120 elements: ROCK4 keeps D_ij within 1e-4 there
  EXPECT_EQ(auto_scheme(std::nextafter(800.0, 0.0)), TimeScheme::Rock4);
  EXPECT_EQ(auto_scheme(800.0), TimeScheme::Rkc);
  EXPECT_EQ(auto_scheme(923.0), TimeScheme::Rkc);  // Fig. 4 at 5 120 elements
}

// The stiffness is 2 over the calibrated Heun limit (stability.hpp), computed here by hand: an NH
// wall (K_s/G_s = 3) at Ca_s = 0.15 and λ = 1, shortest edge 0.06: membrane limit
// 1.4/(1 + 3) · 0.15 · 0.06 = 3.15e-3, below the planar flow's cap 0.02/√2 = 1.41e-2, so
// ρ = 2/3.15e-3 = 634.92. At λ = 5 the limit is (1 + 5)/2 = 3 times longer.
TEST(AutoScheme, TheStiffnessIsTwoOverTheCalibratedHeunLimit) {
  const Scene s = scene_with({"wall.model=\"membrane\"", "wall.law=\"nh\"", "flow.ca_s=0.15", "flow.type=\"planar_hyperbolic\""});
  EXPECT_NEAR(analytic_spectral_radius(s, 0.06), 2.0 / 3.15e-3, 1e-9 * 634.92);  // rounding only
  const Scene viscous = scene_with({"wall.model=\"membrane\"", "wall.law=\"nh\"", "flow.ca_s=0.15",
                                    "flow.type=\"planar_hyperbolic\"", "fluid.viscosity_ratio=5"});
  EXPECT_NEAR(analytic_spectral_radius(viscous, 0.06), 2.0 / 3.15e-3 / 3, 1e-9 * 211.64);
}

// The scene is never rewritten: "auto" stays "auto" in what a run stores, whatever the plan chose.
TEST(TimePlan, TheSceneKeepsAutoAsWritten) {
  const Scene s = scene_with({});
  ASSERT_EQ(s.time.scheme, TimeScheme::Auto);
  const TimePlan p = resolve_time_plan(s, make_reference_mesh(s.mesh));
  EXPECT_NE(p.scheme, TimeScheme::Auto);
  EXPECT_NE(to_toml(s).find("scheme = \"auto\""), std::string::npos);
  EXPECT_EQ(parse_scene(to_toml(s), "again", {}).time.scheme, TimeScheme::Auto);
}

// "auto" with an error-controlled step: the stiffness on the reference mesh decides, as computed
// from the mesh's own shortest edge; the plan records that stiffness.
TEST(TimePlan, AutoPicksByTheStiffnessOfTheReferenceMesh) {
  for (const int level : {2, 3, 4}) {
    const Scene s = scene_with({"mesh.level=" + std::to_string(level)});
    const SurfaceMesh ref = make_reference_mesh(s.mesh);
    const double rho = analytic_spectral_radius(s, min_edge_length(ref));
    const TimePlan p = resolve_time_plan(s, ref);
    EXPECT_EQ(p.stiffness, rho);  // the same function on the same edge: exactly
    EXPECT_EQ(p.scheme, rho < kAutoSchemeRock4BelowStiffness ? TimeScheme::Rock4 : TimeScheme::Rkc) << "level " << level;
    EXPECT_TRUE(p.chosen_by_auto);
    EXPECT_TRUE(p.error_control);
    EXPECT_NE(p.reason.find("auto: the analytic spectral radius"), std::string::npos) << p.reason;
  }
  // Both branches are reached on the built-in wall: coarse meshes are soft, fine ones stiff (ρ ∝ 1/edge).
  EXPECT_EQ(plan_for({"mesh.level=2"}).scheme, TimeScheme::Rock4);
  EXPECT_EQ(plan_for({"mesh.level=4"}).scheme, TimeScheme::Rkc);
}

// ROCK4's "auto" tolerance: 2e-3 · 1280/N for a GSMB wall, 2e-3 · (1280/N)^(8/3) for a plain
// membrane, 2e-3 (or the tolerance before, if looser) past the creases (auto_tolerance.hpp).
TEST(TimePlan, Rock4AutoToleranceFollowsTheMeshAndLoosensAtTheCreases) {
  const TimePlan gsmb = plan_for({"time.scheme=\"rock4\"", "mesh.level=3"});  // 1 280 elements
  EXPECT_EQ(gsmb.scheme, TimeScheme::Rock4);
  EXPECT_FALSE(gsmb.chosen_by_auto);
  EXPECT_DOUBLE_EQ(gsmb.tolerance, 2e-3);
  EXPECT_EQ(gsmb.at_creases, CreaseAction::Loosen);
  EXPECT_DOUBLE_EQ(gsmb.crease_tolerance, 2e-3);

  const TimePlan fine = plan_for({"time.scheme=\"rock4\"", "mesh.level=4"});  // 5 120 elements
  EXPECT_DOUBLE_EQ(fine.tolerance, 2e-3 / 4);
  EXPECT_DOUBLE_EQ(fine.crease_tolerance, 2e-3);

  const TimePlan coarse = plan_for({"time.scheme=\"rock4\"", "mesh.level=2"});  // 320 elements: looser than 2e-3
  EXPECT_DOUBLE_EQ(coarse.tolerance, 8e-3);
  EXPECT_DOUBLE_EQ(coarse.crease_tolerance, 8e-3);

  const TimePlan membrane = plan_for({"time.scheme=\"rock4\"", "mesh.level=4", "wall.model=\"membrane\""});
  EXPECT_NEAR(membrane.tolerance, 2e-3 * std::pow(0.25, 8.0 / 3.0), 1e-15);  // 4.96e-5: pow's rounding only
}

// RKC2's "auto": 1e-5, and at the creases a rewind to t = 0 at 5e-7.
TEST(TimePlan, Rkc2AutoToleranceRewindsAtTheCreases) {
  const TimePlan p = plan_for({"time.scheme=\"rkc\""});
  EXPECT_EQ(p.scheme, TimeScheme::Rkc);
  EXPECT_TRUE(p.error_control);
  EXPECT_TRUE(p.tolerance_auto);
  EXPECT_EQ(p.tolerance, 1e-5);
  EXPECT_EQ(p.at_creases, CreaseAction::Rewind);
  EXPECT_EQ(p.crease_tolerance, 5e-7);
}

TEST(TimePlan, AGivenToleranceFixedStepOrHeunHasNoCreaseAction) {
  const TimePlan given = plan_for({"time.scheme=\"rock4\"", "time.tolerance=3e-4"});
  EXPECT_EQ(given.tolerance, 3e-4);
  EXPECT_FALSE(given.tolerance_auto);
  EXPECT_EQ(given.at_creases, CreaseAction::None);

  const TimePlan fixed = plan_for({"time.dt=0.001"});  // "auto" with a fixed step: RKC2, whatever the stiffness
  EXPECT_EQ(fixed.scheme, TimeScheme::Rkc);
  EXPECT_TRUE(fixed.chosen_by_auto);
  EXPECT_FALSE(fixed.error_control);
  EXPECT_EQ(fixed.at_creases, CreaseAction::None);
  EXPECT_NE(fixed.reason.find("fixed time.dt"), std::string::npos);

  const TimePlan fixed_soft = plan_for({"time.dt=0.001", "mesh.level=2"});  // soft for its mesh, still RKC2
  EXPECT_EQ(fixed_soft.scheme, TimeScheme::Rkc);

  const TimePlan heun = plan_for({"time.scheme=\"heun\""});  // a scheme the user named is never replaced
  EXPECT_EQ(heun.scheme, TimeScheme::Heun);
  EXPECT_FALSE(heun.error_control);
  EXPECT_EQ(heun.at_creases, CreaseAction::None);
  EXPECT_EQ(heun.reason, "as the scene names it");
}

TEST(TimePlan, ToleranceInForceAlongACreaseHistory) {
  TimePlan loosen;
  loosen.at_creases = CreaseAction::Loosen;
  loosen.tolerance = 5e-4;
  loosen.crease_tolerance = 2e-3;
  CreaseHistory h;
  EXPECT_EQ(loosen.tolerance_in_force(h, 1.0), 5e-4);
  h.seen_at = 0.7;
  EXPECT_EQ(loosen.tolerance_in_force(h, 1.0), 2e-3);

  TimePlan rewind;
  rewind.at_creases = CreaseAction::Rewind;
  rewind.tolerance = 1e-5;
  rewind.crease_tolerance = 5e-7;
  CreaseHistory r;
  EXPECT_EQ(rewind.tolerance_in_force(r, 0.5), 1e-5);  // before any crease: loose
  r.tightened = true;
  EXPECT_EQ(rewind.tolerance_in_force(r, 0.5), 5e-7);  // tightened, no crease time: tight for good
  EXPECT_EQ(rewind.tolerance_in_force(r, 50.0), 5e-7);
  r.tight_until = 0.8;
  EXPECT_EQ(rewind.tolerance_in_force(r, 0.79), 5e-7);  // the rewound run up to the crease time: tight
  EXPECT_EQ(rewind.tolerance_in_force(r, 0.8), 1e-5);   // from it on: loose again

  TimePlan none;
  none.tolerance = 3e-4;
  EXPECT_EQ(none.tolerance_in_force(r, 0.9), 3e-4);  // no crease action: the history does not matter
}

TEST(TimePlan, RoundTripsThroughJson) {
  const TimePlan p = plan_for({"time.scheme=\"rock4\"", "mesh.level=4"});
  const TimePlan q = TimePlan::from_json(nlohmann::json::parse(p.to_json().dump()));
  EXPECT_EQ(q.scheme, p.scheme);
  EXPECT_EQ(q.chosen_by_auto, p.chosen_by_auto);
  EXPECT_EQ(q.error_control, p.error_control);
  EXPECT_EQ(q.tolerance_auto, p.tolerance_auto);
  EXPECT_EQ(q.tolerance, p.tolerance);  // bit for bit: JSON keeps 17 digits
  EXPECT_EQ(q.at_creases, p.at_creases);
  EXPECT_EQ(q.crease_tolerance, p.crease_tolerance);
  EXPECT_EQ(q.stiffness, p.stiffness);
  EXPECT_EQ(q.reason, p.reason);
  nlohmann::json bad = p.to_json();
  bad["scheme"] = "auto";  // a stored plan always names the scheme it chose
  EXPECT_THROW(TimePlan::from_json(bad), std::runtime_error);
}

TEST(TimePlan, ARestartKeepsThePlanUnlessATimeKeyOfItChanges) {
  const Scene base = scene_with({});
  EXPECT_TRUE(restart_keeps_time_plan(base, scene_with({"time.t_end=9"})));
  EXPECT_TRUE(restart_keeps_time_plan(base, scene_with({"flow.ca_s=0.3"})));  // a new stiffness does not re-choose
  EXPECT_FALSE(restart_keeps_time_plan(base, scene_with({"time.scheme=\"rkc\""})));
  EXPECT_FALSE(restart_keeps_time_plan(base, scene_with({"time.tolerance=1e-4"})));
  EXPECT_FALSE(restart_keeps_time_plan(base, scene_with({"time.dt=0.01"})));
  const Scene given = scene_with({"time.tolerance=1e-4"});
  EXPECT_TRUE(restart_keeps_time_plan(given, scene_with({"time.tolerance=1e-4"})));
  EXPECT_FALSE(restart_keeps_time_plan(given, scene_with({"time.tolerance=2e-4"})));
}
