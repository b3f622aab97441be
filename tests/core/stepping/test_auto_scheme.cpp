// time.scheme = "auto" (stepping/auto_scheme.hpp): the threshold, the stiffness it is applied to,
// and what a scene says before and after the choice.
#include "capsflow/core/stepping/auto_scheme.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/scene/scene.hpp"
#include "capsflow/core/stepping/stability.hpp"

using namespace capsflow;

TEST(AutoScheme, Rock4BelowTheThresholdAndRkc2FromIt) {
  EXPECT_EQ(auto_scheme(616.0), TimeScheme::Rock4);  // Table 1 at 5 120 elements: must be ROCK4 (item 3)
  EXPECT_EQ(auto_scheme(std::nextafter(800.0, 0.0)), TimeScheme::Rock4);
  EXPECT_EQ(auto_scheme(800.0), TimeScheme::Rkc);
  EXPECT_EQ(auto_scheme(923.0), TimeScheme::Rkc);  // Fig. 4 at 5 120 elements
}

// The stiffness is 2 over the calibrated Heun limit (stability.hpp), computed here by hand: an NH
// wall (K_s/G_s = 3) at Ca_s = 0.15 and λ = 1, shortest edge 0.06: membrane limit
// 1.4/(1 + 3) · 0.15 · 0.06 = 3.15e-3, below the planar flow's cap 0.02/√2 = 1.41e-2, so
// ρ = 2/3.15e-3 = 634.92. At λ = 5 the limit is (1 + 5)/2 = 3 times longer.
TEST(AutoScheme, TheStiffnessIsTwoOverTheCalibratedHeunLimit) {
  const Scene s = parse_scene(default_scene_toml(), "test",
                              {"wall.model=\"membrane\"", "wall.law=\"nh\"", "flow.ca_s=0.15", "flow.type=\"planar_hyperbolic\""});
  EXPECT_NEAR(analytic_spectral_radius(s, 0.06), 2.0 / 3.15e-3, 1e-9 * 634.92);  // rounding only
  const Scene viscous = parse_scene(default_scene_toml(), "test",
                                    {"wall.model=\"membrane\"", "wall.law=\"nh\"", "flow.ca_s=0.15",
                                     "flow.type=\"planar_hyperbolic\"", "fluid.viscosity_ratio=5"});
  EXPECT_NEAR(analytic_spectral_radius(viscous, 0.06), 2.0 / 3.15e-3 / 3, 1e-9 * 211.64);
}

TEST(AutoScheme, ASceneSaysAutoUntilTheChoiceIsMadeForItsMesh) {
  Scene s = parse_scene(default_scene_toml(), "test", {});
  ASSERT_TRUE(s.time.scheme_auto);
  EXPECT_NE(to_toml(s).find("scheme = \"auto\""), std::string::npos);  // what was given, readable again
  // The built-in GH wall (K_s/G_s = 3, Ca_s = 0.1) with a shortest edge of 0.1: ρ = 2/(0.35 · 0.1 · 0.1) = 571.
  resolve_auto_scheme(s, 0.1);
  EXPECT_EQ(s.time.scheme, TimeScheme::Rock4);
  EXPECT_NE(to_toml(s).find("scheme = \"rock4\""), std::string::npos);  // a checkpoint's scene keeps it
  EXPECT_EQ(parse_scene(to_toml(s), "again", {}).time.scheme, TimeScheme::Rock4);

  Scene fixed = parse_scene(default_scene_toml(), "test", {"time.dt=0.001"});
  resolve_auto_scheme(fixed, 0.1);
  EXPECT_EQ(fixed.time.scheme, TimeScheme::Rkc);  // a fixed dt: RKC2, whatever the stiffness

  Scene given = parse_scene(default_scene_toml(), "test", {"time.scheme=\"heun\""});
  resolve_auto_scheme(given, 0.1);
  EXPECT_EQ(given.time.scheme, TimeScheme::Heun);  // a scheme the user named is never replaced
  EXPECT_NE(to_toml(given).find("scheme = \"heun\""), std::string::npos);
}
