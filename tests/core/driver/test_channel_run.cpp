// A capsule in a channel through the whole run (Simulation) and the channel's scene rules: the
// keys that go together, the capsule that does not fit, the channel that is too short or too
// coarse, each refused with one line naming its key; a run's velocity_ratio and lab centroid
// against the right-hand side itself (rhs/channel_dynamics.hpp, tested in
// tests/core/rhs/test_channel_dynamics.cpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "capsflow/core/driver/capsule_placement.hpp"
#include "capsflow/core/driver/simulation.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "tiny_tube_scene.hpp"

namespace capsflow {
namespace {
namespace fs = std::filesystem;

Scene tube_scene(const std::vector<std::string>& overrides = {}) { return test::tiny_tube_scene(overrides); }

// The message of the SceneError that `f` throws, or "" when it throws none.
template <class F>
std::string refusal(F&& f) {
  try {
    f();
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

TEST(ChannelScene, TheChannelAndItsFlowGoTogetherWithOneCapsuleAtViscosityRatioOne) {
  EXPECT_NO_THROW(tube_scene());
  EXPECT_NE(refusal([] { tube_scene({"flow.type=\"simple_shear\""}); }).find("flow.type"), std::string::npos);
  EXPECT_NE(refusal([] { tube_scene({"channel.shape=\"none\""}); }).find("channel.shape"), std::string::npos);
  EXPECT_NE(refusal([] { tube_scene({"fluid.viscosity_ratio=2"}); }).find("fluid.viscosity_ratio"), std::string::npos);
  EXPECT_NE(refusal([] { tube_scene({"layout.count=2", "layout.dx=3"}); }).find("channel.shape"), std::string::npos);
  EXPECT_NE(refusal([] { tube_scene({"channel.radius=0"}); }).find("channel.radius"), std::string::npos);
  EXPECT_NE(refusal([] { tube_scene({"channel.element_size=\"fine\""}); }).find("channel.element_size"), std::string::npos);
}

TEST(ChannelScene, ACapsuleThatDoesNotFitAShortChannelAndACoarseWallAreRefusedByKey) {
  auto check = [](const std::vector<std::string>& o) {
    const Scene s = tube_scene(o);
    return refusal([&] { channel_flow_of(s, make_reference_mesh(s.mesh)); });
  };
  EXPECT_EQ(check({}), "");
  EXPECT_NE(check({"channel.radius=0.98"}).find("channel.radius"), std::string::npos) << "the sphere reaches 1";
  EXPECT_NE(check({"channel.length=7"}).find("channel.length"), std::string::npos) << "2 + 4 × 1.6 = 8.4 needed";
  EXPECT_NE(check({"mesh.level=3", "channel.element_size=0.8"}).find("4 times"), std::string::npos)
      << "more than 4 mean edges (0.15) of the 1280-element sphere";
  EXPECT_NE(check({"channel.element_size=1.7"}).find("channel.element_size"), std::string::npos) << "above the radius";
  // "auto": the capsule's mean edge, not finer than radius/8.
  const Scene s = tube_scene({"channel.element_size=\"auto\""});
  const SurfaceMesh ref = make_reference_mesh(s.mesh);
  EXPECT_NEAR(channel_flow_of(s, ref).geometry.element_size, std::max(mesh_stats(ref).edge_mean, 1.6 / 8), 1e-15);
}

TEST(ChannelScene, AConstrictionIsPlacedInRadiiAndRefusedWhereItDoesNotFit) {
  // Radius 1.6, length 20: the narrow part (half-height 0.8, length 1.6) centred 3.2 downstream.
  const std::vector<std::string> duct = {"channel.shape=\"constricted_duct\"", "channel.length=20"};
  auto flow = [&](std::vector<std::string> o) {
    o.insert(o.begin(), duct.begin(), duct.end());
    const Scene s = tube_scene(o);
    return channel_flow_of(s, make_reference_mesh(s.mesh));
  };
  const ChannelGeometry g = flow({}).geometry;
  EXPECT_EQ(g.shape, ChannelShape::ConstrictedDuct);
  EXPECT_DOUBLE_EQ(g.constriction_height, 0.8);  // 0.5 radius
  EXPECT_DOUBLE_EQ(g.constriction_width, 1.6);   // 1 radius: not narrowed along x3
  EXPECT_DOUBLE_EQ(g.constriction_center, 3.2);  // 2 radii
  EXPECT_DOUBLE_EQ(g.constriction_taper, 0.4);   // auto: one wall element
  EXPECT_NE(refusal([&] { flow({"channel.constriction_center=-0.5"}); }).find("upstream"), std::string::npos)
      << "the capsule would start inside the constriction";
  EXPECT_NE(refusal([&] { flow({"channel.constriction_center=5.5"}); }).find("2 radii"), std::string::npos)
      << "the constriction would end 0.8 from the outlet cap";
  EXPECT_NE(refusal([] { tube_scene({"channel.constriction_height=0.4"}); }).find("channel.constriction_height"),
            std::string::npos)
      << "a tube has no constriction";
  EXPECT_NE(refusal([] { tube_scene({"channel.shape=\"constricted_duct\"", "channel.constriction_width=1.5"}); })
                .find("channel.constriction_width"),
            std::string::npos)
      << "wider than the duct";
}

TEST(ChannelRun, WritesTheCapsulesSpeedThroughTheChannelAndItsLabPosition) {
  const fs::path dir = fs::temp_directory_path() / ("capsflow-channel-run-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  RunOptions o;
  o.scene = tube_scene();
  o.output_dir = dir.string();
  o.threads = 1;
  ASSERT_EQ(Simulation(o).run(), 0);
  std::ifstream f(dir / "summary.json");
  const nlohmann::json s = nlohmann::json::parse(f);
  EXPECT_EQ(s.at("stop_reason"), "t_end");
  // The run's first evaluation is the right-hand side's at the reference state, bit for bit.
  const SurfaceMesh ref = make_reference_mesh(o.scene.mesh);
  ChannelDynamics d(o.scene, ref, channel_flow_of(o.scene, ref), 1);
  Points v;
  d.evaluate(ref.vertices, v, {EvaluationHint::Role::Trajectory, 0});
  std::ifstream csv(dir / "timeseries.csv");
  std::string header, first;
  std::getline(csv, header), std::getline(csv, first);
  std::vector<std::string> names, values;
  for (std::stringstream h(header); std::getline(h, names.emplace_back(), ',');) {}
  for (std::stringstream r(first); std::getline(r, values.emplace_back(), ',');) {}
  const auto column = std::find(names.begin(), names.end(), "velocity_ratio") - names.begin();
  ASSERT_LT(column, static_cast<long>(names.size()) - 1) << "timeseries.csv has velocity_ratio";
  EXPECT_EQ(std::stod(values[static_cast<std::size_t>(column)]), d.axial_velocity());
  // Confined, the capsule is slower than Poiseuille's mean over its volume unconfined (1.84 at this
  // radius, rhs test) and faster than the mean flow.
  const double U = s.at("velocity_ratio").get<double>();
  EXPECT_GT(U, 1.0);
  EXPECT_LT(U, 2 * (1 - 2.0 / (5 * 1.6 * 1.6)));
  // The lab centroid travels with the capsule: U t to within U's change over the run (2 %).
  EXPECT_NEAR(s.at("centroid")[0].get<double>() / (U * 0.2), 1, 0.02);
  // Barely deformed, its rear is convex: positive curvature (on 80 elements the fit's patch of 2.5
  // edges spans most of the rear half, where a sphere's ρ⁴ term adds to it: 1.88 measured).
  EXPECT_GT(s.at("rear_curvature").get<double>(), 0.5);
  EXPECT_LT(s.at("rear_curvature").get<double>(), 3.0);
  EXPECT_EQ(s.at("channel").at("shape"), "tube");
  EXPECT_GT(s.at("channel").at("wall_nodes").get<long>(), 0);
  // The wall for ParaView: its mesh and last traction, and an XDMF grid naming them.
  const long wall_nodes = s.at("channel").at("wall_nodes").get<long>();
  EXPECT_TRUE(fs::exists(dir / "channel.h5"));
  std::ifstream xmf(dir / "channel.xmf");
  const std::string text((std::istreambuf_iterator<char>(xmf)), std::istreambuf_iterator<char>());
  for (const std::string& item : {std::string("channel.h5:/triangles"), std::string("channel.h5:/positions"),
                                  std::string("channel.h5:/traction"), "Dimensions=\"" + std::to_string(wall_nodes) + " 3\""})
    EXPECT_NE(text.find(item), std::string::npos) << item;
  fs::remove_all(dir);
}

// A restart continues bit for bit: the checkpoint holds the wall solve's warm start (the channel
// wall's traction) and the closest approach so far; output times between steps put the traction
// back (dense output), so the half-way checkpoint does not move the trajectory either. Times exact
// in binary, so that the first part ends where the uninterrupted run's step does.
TEST(ChannelRun, ARestartContinuesBitForBit) {
  const fs::path base = fs::temp_directory_path() / ("capsflow-channel-restart-" + std::to_string(::getpid()));
  const fs::path straight = base / "straight", first = base / "first", second = base / "second";
  fs::remove_all(base);
  const std::vector<std::string> times = {"output.every=0.0625", "output.checkpoint_every=0.125"};
  auto options = [&](const std::string& t_end, const fs::path& dir) {
    std::vector<std::string> o = times;
    o.push_back("time.t_end=" + t_end);
    RunOptions r;
    r.scene = tube_scene(o);
    r.output_dir = dir.string();
    r.threads = 1;
    return r;
  };
  Simulation whole(options("0.25", straight));
  ASSERT_EQ(whole.run(), 0);
  ASSERT_EQ(Simulation(options("0.125", first)).run(), 0);
  RunOptions r;
  r.restart = (first / "checkpoint.h5").string();
  r.restart_overrides = {"time.t_end=0.25"};
  r.output_dir = second.string();
  r.threads = 1;
  Simulation continued(r);
  ASSERT_EQ(continued.run(), 0);
  EXPECT_EQ((continued.positions() - whole.positions()).cwiseAbs().maxCoeff(), 0.0);
  auto summary = [](const fs::path& dir) {
    std::ifstream f(dir / "summary.json");
    return nlohmann::json::parse(f);
  };
  const nlohmann::json a = summary(straight), b = summary(second);
  EXPECT_EQ(a.at("velocity_ratio"), b.at("velocity_ratio"));
  EXPECT_EQ(a.at("pressure_drop"), b.at("pressure_drop"));
  EXPECT_EQ(a.at("centroid"), b.at("centroid"));  // the lab position carries over too
  EXPECT_EQ(a.at("channel").at("closest_approach"), b.at("channel").at("closest_approach"));
  fs::remove_all(base);
}

TEST(ChannelRun, ACapsuleCloserToTheWallThanContactMinGapStopsTheRunUnderStopOn) {
  // The tiny tube's capsule starts 0.6 from the wall, 0.94 of the nearest wall element's longest
  // edge: a min_gap of 3 element sizes begins the surface_gap condition at once; with stop_on the
  // run stops there, naming it (exit 3), and summary.json keeps the closest approach.
  const fs::path dir = fs::temp_directory_path() / ("capsflow-channel-gap-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  RunOptions o;
  o.scene = tube_scene({"contact.min_gap=3", "time.stop_on=[\"surface_gap\"]"});
  o.output_dir = dir.string();
  o.threads = 1;
  EXPECT_EQ(Simulation(o).run(), 3);
  std::ifstream f(dir / "summary.json");
  const nlohmann::json s = nlohmann::json::parse(f);
  EXPECT_EQ(s.at("stop_reason"), "surface_gap");
  const nlohmann::json& c = s.at("channel").at("closest_approach");
  EXPECT_EQ(c.at("episodes"), 1);
  EXPECT_LT(c.at("min_gap").get<double>(), 3.0);
  EXPECT_GT(c.at("min_gap").get<double>(), 0.5);  // 0.94 of the longest wall edge at the start
  fs::remove_all(dir);
}

}  // namespace
}  // namespace capsflow
