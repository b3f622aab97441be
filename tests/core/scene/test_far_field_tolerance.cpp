// fluid.tolerance = "auto" resolved with the time keys (far_field_tolerance,
// src/scene/boundary_integral_options.cpp; docs/boundary-integral.md §4.3.2): every branch, and what
// the operators' options receive.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "capsflow/core/scene/boundary_integral_options.hpp"
#include "capsflow/core/scene/scene.hpp"

using namespace capsflow;

namespace {
FarFieldTolerance resolved(const std::vector<std::string>& overrides) {
  return far_field_tolerance(parse_scene(default_scene_toml(), "test", overrides));
}
}  // namespace

TEST(FarFieldTolerance, AutoIsTheDefaultAndLoosensOnlyTheFmmUnderErrorControl) {
  const Scene s = parse_scene("", "empty");
  EXPECT_TRUE(s.fluid.tolerance_auto);
  EXPECT_EQ(s.fluid.tolerance, 1e-6);  // what the direct sums and the crossover read
  const FarFieldTolerance t = far_field_tolerance(s);
  EXPECT_EQ(t.tolerance, 1e-6);
  EXPECT_EQ(t.fmm_tolerance, 1e-5);
  EXPECT_EQ(t.reason.rfind("auto", 0), 0u) << t.reason;
  // Both time schemes with error control, the tolerance "auto" or looser than 1e-5: 1e-5.
  EXPECT_EQ(resolved({"time.scheme=rkc"}).fmm_tolerance, 1e-5);
  EXPECT_EQ(resolved({"time.scheme=rock4"}).fmm_tolerance, 1e-5);
  EXPECT_EQ(resolved({"time.tolerance=1e-3"}).fmm_tolerance, 1e-5);
}

TEST(FarFieldTolerance, AGivenTighterTimeToleranceTightensTheFmmDownToTheSmallestAccepted) {
  EXPECT_EQ(resolved({"time.tolerance=1e-7"}).fmm_tolerance, 1e-7);
  EXPECT_EQ(resolved({"time.tolerance=1e-9"}).fmm_tolerance, 1e-8);  // fluid.tolerance's range starts at 1e-8
  EXPECT_EQ(resolved({"time.tolerance=1e-7"}).tolerance, 1e-6);      // the direct sums keep theirs
}

TEST(FarFieldTolerance, WithoutErrorControlOrAtViscosityRatioNotOneBothStayAt1e6) {
  for (const std::vector<std::string>& o : std::vector<std::vector<std::string>>{
           {"time.scheme=heun"}, {"time.dt=1e-3"}, {"fluid.viscosity_ratio=5"}}) {
    const FarFieldTolerance t = resolved(o);
    EXPECT_EQ(t.tolerance, 1e-6) << o[0];
    EXPECT_EQ(t.fmm_tolerance, 1e-6) << o[0];
  }
}

TEST(FarFieldTolerance, AGivenValueIsThePromiseOfBothBackEnds) {
  const FarFieldTolerance t = resolved({"fluid.tolerance=1e-4"});
  EXPECT_EQ(t.tolerance, 1e-4);
  EXPECT_EQ(t.fmm_tolerance, 1e-4);
  EXPECT_EQ(t.reason, "given");
  const Scene s = parse_scene(default_scene_toml(), "test", {"fluid.tolerance=1e-6"});
  EXPECT_FALSE(s.fluid.tolerance_auto);
  EXPECT_EQ(far_field_tolerance(s).fmm_tolerance, 1e-6);
}

TEST(FarFieldTolerance, TheOperatorsOptionsCarryIt) {
  const Scene s = parse_scene(default_scene_toml(), "test");
  const SingleLayerOptions o = boundary_integral_options(s);
  EXPECT_EQ(o.tolerance, 1e-6);
  EXPECT_EQ(o.fmm_tolerance, 1e-5);
  // The double layer (λ ≠ 1) never takes the looser FMM tolerance.
  const Scene l = parse_scene(default_scene_toml(), "test", {"fluid.viscosity_ratio=5"});
  const DoubleLayerOptions d = double_layer_options(l);
  EXPECT_EQ(d.tolerance, 1e-6);
  EXPECT_EQ(d.fmm_tolerance, 0.0);
}

TEST(FarFieldTolerance, TheKeyReadsAutoOrANumberAndRefusesOtherWords) {
  const Scene a = parse_scene("[fluid]\ntolerance = \"auto\"\n", "a");
  EXPECT_TRUE(a.fluid.tolerance_auto);
  const Scene n = parse_scene("[fluid]\ntolerance = 3e-5\n", "n");
  EXPECT_FALSE(n.fluid.tolerance_auto);
  EXPECT_EQ(n.fluid.tolerance, 3e-5);
  EXPECT_THROW(parse_scene("[fluid]\ntolerance = \"fast\"\n", "w"), SceneError);
  EXPECT_THROW(parse_scene("[fluid]\ntolerance = 1e-9\n", "w"), SceneError);  // below the sums' accuracy
  // The resolved TOML keeps "auto" as written (a checkpoint's scene resolves the same way again).
  EXPECT_NE(to_toml(a).find("tolerance = \"auto\""), std::string::npos);
  EXPECT_EQ(to_toml(parse_scene(to_toml(n), "again")), to_toml(n));
}
