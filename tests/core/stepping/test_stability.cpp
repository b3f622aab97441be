// The stable time step (stepping/stability.hpp) computed by hand from its formulas: membrane,
// bending and flow limits, which one limits, and the viscosity ratio's factor (1 + λ)/2.
#include "capsflow/core/stepping/stability.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/scene/scene.hpp"

using namespace capsflow;

namespace {
Scene scene_with(const std::vector<std::string>& sets) { return parse_scene(default_scene_toml(), "test", sets); }
}  // namespace

// Generalized Hooke with ν = 0.5 (K_s/G_s = 3): membrane limit 1.4/(1 + 3) · Ca_s · dx; GSMB bending
// 0.7 · 6(1 − ν)/α² · Ca_s · dx³; the flow's cap 0.02/|L|. Tolerance: rounding only.
TEST(Stability, LimitsFollowTheirFormulas) {
  const Scene s = scene_with({"wall.law=\"gh\"", "wall.poisson=0.5", "wall.thickness=0.05", "flow.ca_s=0.2",
                              "flow.type=\"simple_shear\""});
  const double dx = 0.1;
  const StabilityEstimate e = stability_estimate(s, dx);
  EXPECT_NEAR(e.membrane, 1.4 / 4 * 0.2 * dx, 1e-15);
  EXPECT_NEAR(e.bending, 0.7 * 6 * 0.5 / (0.05 * 0.05) * 0.2 * dx * dx * dx, 1e-15);
  EXPECT_NEAR(e.flow, 0.02 / 1.0, 1e-15);  // simple shear: |L| = 1
  EXPECT_EQ(e.limit(), std::min({e.membrane, e.bending, e.flow}));
  EXPECT_EQ(e.limiting(), "membrane");  // 7e-3 < 0.02 < 0.168
  EXPECT_NEAR(analytic_spectral_radius(s, dx), 2.0 / e.membrane, 1e-9);
}

TEST(Stability, APlainMembraneHasNoBendingLimitAndASoftWallIsLimitedByTheFlow) {
  const Scene m = scene_with({"wall.model=\"membrane\"", "flow.ca_s=10", "wall.law=\"gh\"", "wall.poisson=0.5",
                              "flow.type=\"simple_shear\""});
  const StabilityEstimate e = stability_estimate(m, 0.1);
  EXPECT_TRUE(std::isinf(e.bending));
  EXPECT_EQ(e.limiting(), "flow");  // membrane 0.35 > flow 0.02
}

TEST(Stability, AViscousInteriorLengthensTheLimitByOnePlusLambdaOverTwo) {
  const Scene a = scene_with({"flow.ca_s=0.05"}), b = scene_with({"flow.ca_s=0.05", "fluid.viscosity_ratio=4"});
  EXPECT_NEAR(stability_estimate(b, 0.05).membrane / stability_estimate(a, 0.05).membrane, 2.5, 1e-12);
  EXPECT_NEAR(stability_estimate(b, 0.05).bending / stability_estimate(a, 0.05).bending, 2.5, 1e-12);
}
