// The variants of a study (study/study_plan.hpp) and the ETA's cost model (study/cost_model.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "capsflow/core/study/cost_model.hpp"
#include "capsflow/core/study/study_plan.hpp"

using namespace capsflow;
using namespace capsflow::study;

namespace {
// The message f throws, or "" when it does not.
std::string error(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(StudyPlan, VariantsAreEveryLevelTimesEveryCombinationCoarseFirst) {
  const StudyPlan p = make_study_plan("", {"wall.law=nh"}, parse_levels("4,3"),
                                      {parse_vary("fluid.geometry=flat,curved"), parse_vary("fluid.backend=fmm,direct")});
  EXPECT_EQ(p.levels, (std::vector<int>{3, 4}));
  ASSERT_EQ(p.variants.size(), 8u);
  EXPECT_EQ(p.families, (std::vector<std::string>{"geometry=flat_backend=fmm", "geometry=flat_backend=direct",
                                                  "geometry=curved_backend=fmm", "geometry=curved_backend=direct"}));
  EXPECT_EQ(p.variants[0].name, "geometry=flat_backend=fmm_L3");
  EXPECT_EQ(p.variants[7].name, "geometry=curved_backend=direct_L4");
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(p.variants[i].level, 3);  // coarse level first
  const Variant& v = p.variants[6];  // curved, fmm, level 4
  EXPECT_EQ(v.scene.fluid.geometry, SurfaceGeometry::Curved);
  EXPECT_EQ(v.scene.fluid.backend, BackendRequest::Fmm);
  EXPECT_EQ(v.scene.wall.law, shell::LawKind::NeoHookean);  // the study's --set applies to all
  EXPECT_EQ(v.scene.mesh.level, 4);
  EXPECT_EQ(v.elements, 20 * 256);
  const StudyPlan single = make_study_plan("", {}, parse_levels("2"), {});
  ASSERT_EQ(single.variants.size(), 1u);
  EXPECT_EQ(single.variants[0].name, "L2");
  EXPECT_EQ(family_label(single.variants[0].family), "scene");
}

TEST(StudyPlan, AxesSharingALeafAreNamedByTheirFullKeyAndValuesAreMadeSafe) {
  const StudyPlan p = make_study_plan("", {"time.scheme=rkc"}, {3},
                                      {parse_vary("fluid.tolerance=1e-6,1e-4"), parse_vary("time.tolerance=1e-5")});
  EXPECT_EQ(p.variants[0].name, "fluid.tolerance=1e-6_time.tolerance=1e-5_L3");
  // Commas inside brackets or quotes belong to the value.
  const VaryAxis a = parse_vary("flow.gradient=[[0,1,0],[0,0,0],[0,0,0]],\"a,b\"");
  ASSERT_EQ(a.values.size(), 2u);
  EXPECT_EQ(a.values[0], "[[0,1,0],[0,0,0],[0,0,0]]");
  EXPECT_EQ(a.values[1], "\"a,b\"");
}

TEST(StudyPlan, BadLevelsAndAxesAreOneLineErrors) {
  EXPECT_NE(error([] { parse_levels("3,5"); }).find("consecutive"), std::string::npos);
  EXPECT_NE(error([] { parse_levels("3,,4"); }).find("'' is not an integer"), std::string::npos);
  EXPECT_NE(error([] { parse_vary("geometry=flat"); }).find("section.key"), std::string::npos);
  EXPECT_NE(error([] { parse_vary("fluid.geometry=flat,flat"); }).find("given twice"), std::string::npos);
  EXPECT_NE(error([] { make_study_plan("", {}, {}, {}); }).find("--levels"), std::string::npos);
  EXPECT_NE(error([] { make_study_plan("", {"mesh.file=x.off"}, {3}, {}); }).find("mesh.file"), std::string::npos);
  EXPECT_NE(error([] { make_study_plan("", {}, {3, 4, 5, 6, 7, 8, 9, 10}, {}); }).find("mesh.level"), std::string::npos);
}

TEST(CostModel, RecoversAPowerLawAndUsesTheSchemeExponentUntilTwoSizesAreMeasured) {
  CostModel m(1.5);
  EXPECT_EQ(m.predict("f", 1280), 0.0);  // nothing measured
  m.add("flat", 1280, 10.0);
  EXPECT_FALSE(m.fitted());
  EXPECT_NEAR(m.predict("flat", 5120), 10.0 * std::pow(4.0, 1.5), 1e-9);  // the assumed N^1.5
  // t = c_f N^1.8 with a family factor of 1.5: the common exponent is recovered exactly, and each
  // family keeps its own constant (rounding of log/exp only: 1e-9 relative).
  m = CostModel(1.5);
  for (long n : {1280L, 5120L}) {
    m.add("flat", n, 1e-4 * std::pow(static_cast<double>(n), 1.8));
    m.add("curved", n, 1.5e-4 * std::pow(static_cast<double>(n), 1.8));
  }
  EXPECT_TRUE(m.fitted());
  EXPECT_NEAR(m.exponent(), 1.8, 1e-12);
  EXPECT_NEAR(m.predict("curved", 20480) / (1.5e-4 * std::pow(20480.0, 1.8)), 1.0, 1e-9);
  // An implausible slope is clamped (a noisy or cache-bound measurement must not give an ETA of days).
  CostModel noisy(2.0);
  noisy.add("f", 1000, 1.0);
  noisy.add("f", 2000, 100.0);
  EXPECT_EQ(noisy.exponent(), CostModel::kMaxExponent);
}

TEST(StudyPlan, TwoSpellingsOfOneValueAreRefusedNamingBoth) {
  // 0.1 and 1e-1 are the same Ca_s: the two families would be the same runs (issue: identical families).
  try {
    make_study_plan("", {}, {1, 2}, {parse_vary("flow.ca_s=0.1,0.2,1e-1")});
    FAIL() << "equal values accepted";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("--vary: --vary flow.ca_s=0.1,0.2,1e-1 gives the same scene twice: ca_s=0.1 and ca_s=1e-1"),
              std::string::npos) << m;
  }
  // Different values are kept, however close.
  EXPECT_EQ(make_study_plan("", {}, {1}, {parse_vary("flow.ca_s=0.1,0.1000001")}).families.size(), 2u);
}

// `study --levels -1,0` and `--vary foo.bar=1,2` said "--set mesh.level: ..." and
// "--set foo.bar: ...", blaming a --set the user never gave. Each error now names the option.
TEST(StudyPlan, SceneErrorsNameTheOptionThatGaveTheKey) {
  const std::string levels = error([] { make_study_plan("", {}, parse_levels("-1,0"), {}); });
  EXPECT_EQ(levels.rfind("--levels mesh.level: -1 is out of range: must be in [0, 9]", 0), 0u) << levels;
  const std::string unknown = error([] { make_study_plan("", {}, {2}, {parse_vary("foo.bar=1,2")}); });
  EXPECT_EQ(unknown.rfind("--vary foo.bar: unknown section [foo]", 0), 0u) << unknown;
  const std::string value = error([] { make_study_plan("", {}, {2}, {parse_vary("fluid.geometry=flat,bent")}); });
  EXPECT_EQ(value.rfind("--vary fluid.geometry: 'bent' is not one of", 0), 0u) << value;
  // What --set gave is still blamed on --set.
  const std::string set = error([] { make_study_plan("", {"fluid.verify_every=-2"}, {2}, {}); });
  EXPECT_EQ(set.rfind("--set fluid.verify_every: -2 is out of range", 0), 0u) << set;
}

TEST(StudyPlan, AChannelsWallIsRefinedWithTheCapsuleUnlessItsSizeIsGiven) {
  // element_size "auto" floors the wall at radius/8 = 0.139: a study sets it to the capsule's mean
  // edge at every level instead, so that wall and capsule halve together (ratio 2 to 1 %: the
  // icosphere's edges shrink by 2 per level up to its curvature's O(h²)).
  const std::vector<std::string> tube = {"flow.type=\"poiseuille\"", "channel.shape=\"tube\"", "channel.radius=1.111",
                                         "mesh.shape=\"sphere\""};
  const StudyPlan p = make_study_plan("", tube, parse_levels("2,3,4"), {});
  ASSERT_EQ(p.variants.size(), 3u);
  for (std::size_t i = 0; i + 1 < 3; ++i)
    EXPECT_NEAR(p.variants[i].scene.channel.element_size / p.variants[i + 1].scene.channel.element_size, 2.0, 0.02);
  EXPECT_LT(p.variants[2].scene.channel.element_size, 1.111 / 8);  // below the auto rule's floor
  EXPECT_NE(p.variants[2].overrides.back().find("channel.element_size="), std::string::npos);  // stated in the command
  std::vector<std::string> given = tube;
  given.push_back("channel.element_size=0.2");
  for (const Variant& v : make_study_plan("", given, parse_levels("2,3"), {}).variants)
    EXPECT_EQ(v.scene.channel.element_size, 0.2);  // exact: the user's
}
