// Several capsules through the whole run (Simulation): far apart they move as one alone; a
// point-symmetric pair stays point-symmetric in every output; a restart continues bit for bit;
// overlapping capsules are refused before the folder exists; the closest approach is watched and
// stops the run under time.stop_on. The right-hand side itself: tests/core/rhs/test_suspension_dynamics.cpp.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capsflow/core/driver/simulation.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "tiny_pair_scene.hpp"

namespace capsflow {
namespace {
namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("capsflow-several-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

nlohmann::json summary_of(const fs::path& dir) {
  std::ifstream f(dir / "summary.json");
  return nlohmann::json::parse(f);
}

RunOptions options(const std::vector<std::string>& overrides, const fs::path& dir, const std::string& extra = "") {
  RunOptions o;
  o.scene = parse_scene(std::string(test::kTinyShearScene) + extra, "pair.toml", overrides);
  o.output_dir = dir.string();
  o.threads = 1;
  return o;
}

TEST(SeveralCapsulesRun, TwoCapsulesFortyRadiiApartMoveAsOneAlone) {
  const fs::path one = fresh_dir("alone"), two = fresh_dir("far");
  // At (±20, 0, 0) the imposed flow is zero at each centre; the other capsule's disturbance there
  // is a stresslet field of relative size (a/r)² ≈ 6e-4 of Ca_s, its strain (a/r)³ ≈ 1e-5.
  ASSERT_EQ(Simulation(options({}, one)).run(), 0);
  ASSERT_EQ(Simulation(options({"layout.count=2", "layout.dx=40"}, two)).run(), 0);
  const nlohmann::json a = summary_of(one), b = summary_of(two);
  ASSERT_EQ(b.at("capsules").size(), 2u);
  for (int k = 0; k < 2; ++k)
    for (const char* d : {"D12", "D13", "D23"})
      // 1e-4: the accuracy the automatic time tolerance holds D_ij to (docs/time-integration.md §5.3);
      // the two runs take different steps (the union's error norm), the disturbance is ≈ 1e-5.
      EXPECT_NEAR(b["capsules"][k][d].get<double>(), a[d].get<double>(), 1e-4) << "capsule " << k + 1 << " " << d;
  // Each stays where the flow is zero, within the other's far-field drift.
  EXPECT_NEAR(b["capsules"][0]["centroid"][0].get<double>(), -20, 1e-3);
  EXPECT_NEAR(b["capsules"][1]["centroid"][0].get<double>(), 20, 1e-3);
  fs::remove_all(one);
  fs::remove_all(two);
}

TEST(SeveralCapsulesRun, EachCapsuleMovesWithTheFlowAtItsCentre) {
  const fs::path dir = fresh_dir("velocity");
  // At (0, ∓20, 0) in v∞ = x2 e1 each capsule is carried at (∓20, 0, 0); a sphere in a linear flow
  // translates with the flow at its centre (Faxén), the other capsule adds (a/r)² ≈ 6e-4 of Ca_s·a.
  ASSERT_EQ(Simulation(options({"layout.count=2", "layout.dy=40"}, dir)).run(), 0);
  const nlohmann::json s = summary_of(dir);
  for (int k = 0; k < 2; ++k) {
    const nlohmann::json& c = s.at("capsules")[k];
    const double y = c.at("centroid")[1].get<double>();
    EXPECT_NEAR(y, k == 0 ? -20 : 20, 1e-3) << "capsule " << k + 1 << " stays on its streamline";
    EXPECT_NEAR(c.at("velocity")[0].get<double>(), y, 1e-3) << "capsule " << k + 1 << ": the flow at its centre";
    EXPECT_NEAR(c.at("velocity")[1].get<double>(), 0, 1e-3);
    EXPECT_NEAR(c.at("velocity")[2].get<double>(), 0, 1e-3);
    // ... and where it went: x1 = y t after t = 0.4.
    EXPECT_NEAR(c.at("centroid")[0].get<double>(), 0.4 * y, 1e-3);
  }
  fs::remove_all(dir);
}

TEST(SeveralCapsulesRun, APointSymmetricPairStaysPointSymmetric) {
  const fs::path dir = fresh_dir("symmetric");
  // x → −x maps simple shear onto itself and the icosphere onto itself (its vertices come in ±
  // pairs), so it maps capsule 1 (at (2, −0.25, 0)) onto capsule 2 (at (−2, 0.25, 0)).
  ASSERT_EQ(Simulation(options({"layout.count=2", "layout.dx=-4", "layout.dy=0.5"}, dir)).run(), 0);
  const nlohmann::json s = summary_of(dir);
  const nlohmann::json &c1 = s.at("capsules")[0], &c2 = s.at("capsules")[1];
  for (const char* d : {"D12", "D13", "D23", "area", "volume"})
    EXPECT_NEAR(c1[d].get<double>(), c2[d].get<double>(), 1e-11) << d << ": round-off of sums in another order";
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(c1["centroid"][i].get<double>(), -c2["centroid"][i].get<double>(), 1e-11) << "centroid " << i;
    EXPECT_NEAR(c1["velocity"][i].get<double>(), -c2["velocity"][i].get<double>(), 1e-11) << "velocity " << i;
  }
  // The pair moved with the shear: capsule 1 (below the plane x2 = 0) backwards.
  EXPECT_LT(c1["centroid"][0].get<double>(), 2 - 0.05) << "x1 decreases by about 0.25 · 0.4";
  // 2 radii between the surfaces, the level-1 sphere's longest edges about 0.7: within the 3 sizes
  // of the cross search, above contact.min_gap.
  EXPECT_GT(s.at("surface_gap").at("min_gap").get<double>(), 2.0);
  EXPECT_EQ(s.at("surface_gap").at("episodes"), 0);
  fs::remove_all(dir);
}

TEST(SeveralCapsulesRun, ARestartContinuesBitForBit) {
  const fs::path dir = fresh_dir("straight"), first = fresh_dir("first"), second = fresh_dir("second");
  const std::vector<std::string> pair = {"layout.count=2", "layout.dx=-3", "layout.dy=0.6"};
  Simulation straight(options(pair, dir));
  ASSERT_EQ(straight.run(), 0);
  // The first half, then a restart from its final checkpoint to the same end.
  ASSERT_EQ(Simulation(options({pair[0], pair[1], pair[2], "time.t_end=0.2"}, first)).run(), 0);
  RunOptions r;
  r.restart = (first / "checkpoint.h5").string();
  r.restart_overrides = {"time.t_end=0.4"};
  r.output_dir = second.string();
  r.threads = 1;
  Simulation continued(r);
  ASSERT_EQ(continued.run(), 0);
  ASSERT_EQ(continued.positions().rows(), straight.positions().rows());
  EXPECT_EQ((continued.positions() - straight.positions()).cwiseAbs().maxCoeff(), 0.0)
      << "the checkpoint holds every capsule's wall, the time plan and the scheme's state";
  EXPECT_EQ(summary_of(second).at("capsules").size(), 2u);
  for (const fs::path& p : {dir, first, second}) fs::remove_all(p);
}

TEST(SeveralCapsulesRun, TheTimePlanIsTheStiffestCapsules) {
  const fs::path pair = fresh_dir("unlike"), alone = fresh_dir("stiff-alone");
  // Capsule 2 is four times finer and ten times stiffer in area dilation: its analytic spectral
  // radius sets the stable step of both, so the pair's plan is that of capsule 2 alone.
  const std::string own = "[[capsule]]\ncenter = [-3, 0, 0]\n[[capsule]]\ncenter = [3, 0, 0]\nmesh.level = 2\nwall.skalak_c = 10\n";
  ASSERT_EQ(Simulation(options({"time.t_end=0.02"}, pair, own)).run(), 0);
  ASSERT_EQ(Simulation(options({"time.t_end=0.02", "mesh.level=2", "wall.skalak_c=10"}, alone)).run(), 0);
  const nlohmann::json p = summary_of(pair), a = summary_of(alone);
  // The same formula on the same capsule; moved to x1 = 3 its edge lengths differ in the last bits.
  EXPECT_NEAR(p.at("time_plan").at("stiffness").get<double>(), a.at("time_plan").at("stiffness").get<double>(),
              1e-12 * a.at("time_plan").at("stiffness").get<double>());
  EXPECT_EQ(p.at("time_plan").at("scheme"), a.at("time_plan").at("scheme"));
  EXPECT_EQ(p.at("elements").get<long>(), 80 + 320) << "a level-1 and a level-2 icosphere";
  fs::remove_all(pair);
  fs::remove_all(alone);
}

TEST(SeveralCapsulesRun, OverlappingCapsulesAreRefusedBeforeTheFolderExists) {
  const fs::path dir = fresh_dir("overlap");
  try {
    Simulation(options({"layout.count=2", "layout.dx=1.5"}, dir)).set_up();
    FAIL() << "two unit spheres 1.5 apart overlap";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("capsules 1 and 2 overlap where they start"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("layout.dx"), std::string::npos) << "names the key to change: " << e.what();
  }
  EXPECT_FALSE(fs::exists(dir));
  try {  // nearly coincident: nodes of each behind the other's faces
    Simulation(options({}, dir, "[[capsule]]\ncenter = [0, 0, 0]\n[[capsule]]\ncenter = [0.05, 0, 0]\n")).set_up();
    FAIL() << "capsules 0.05 apart overlap";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("capsules 1 and 2 overlap"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("capsule 2's center"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir));
  try {  // coincident: every node on the other's surface
    Simulation(options({}, dir, "[[capsule]]\ncenter = [1, 0, 0]\n[[capsule]]\ncenter = [1, 0, 0]\n")).set_up();
    FAIL() << "coincident capsules overlap";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("capsules 1 and 2 overlap"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir));
}

TEST(SeveralCapsulesRun, TheClosestApproachIsWatchedAndStopsTheRunWhenAsked) {
  const fs::path dir = fresh_dir("gap");
  // 0.1 apart along x2, a seventh of the level-1 sphere's longest edge (about 0.7): below
  // min_gap = 0.5 where they start, so the run stops at its first step.
  RunOptions o = options({"layout.count=2", "layout.dy=2.1", "contact.min_gap=0.5", "time.stop_on=[\"surface_gap\"]"}, dir);
  Simulation sim(o);
  EXPECT_EQ(sim.run(), 3) << "a health stop: the state is not to be trusted (exit 3)";
  const nlohmann::json s = summary_of(dir);
  EXPECT_EQ(s.at("stop_reason"), "surface_gap");
  EXPECT_LT(s.at("surface_gap").at("min_gap").get<double>(), 0.5);
  EXPECT_EQ(s.at("surface_gap").at("episodes"), 1);
  EXPECT_EQ(s.at("surface_gap").at("capsules"), nlohmann::json({1, 2}));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace capsflow
