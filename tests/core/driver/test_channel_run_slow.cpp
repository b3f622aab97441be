// A capsule through a constricted duct to its outlet (label slow: ~35 s on 2 threads): the run
// stops with stop_reason "outlet" and exit 0 once the capsule's front is within 1.25 channel radii
// of the outlet cap (rhs/channel_dynamics.hpp), before t_end and before any stage would come
// within one radius (which evaluate() refuses).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capsflow/core/driver/simulation.hpp"
#include "capsflow/core/io/checkpoint.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "tiny_tube_scene.hpp"

namespace capsflow {
namespace {
namespace fs = std::filesystem;

// The tiny tube made a duct of half-width 1.6 narrowed to 0.9 × 1.6 = 1.44 along x2 (wider than
// the capsule: it passes without squeezing), outlet cap at x1 = 7.7.
const std::vector<std::string> kTinyConstriction = {
    "channel.shape=\"constricted_duct\"", "channel.length=15.4", "channel.constriction_height=0.9",
    "time.t_end=10", "output.every=0.5", "output.checkpoint_every=0.5"};

TEST(ChannelRun, ACapsuleThatReachesAConstrictedDuctsOutletStopsThereNamingIt) {
  const fs::path dir = fs::temp_directory_path() / ("capsflow-channel-outlet-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  RunOptions o;
  o.scene = test::tiny_tube_scene(kTinyConstriction);
  o.output_dir = dir.string();
  o.threads = 2;
  EXPECT_EQ(Simulation(o).run(), 0);  // the capsule has passed the channel: a finished run
  std::ifstream f(dir / "summary.json");
  const nlohmann::json s = nlohmann::json::parse(f);
  EXPECT_EQ(s.at("stop_reason"), "outlet");
  EXPECT_LT(s.at("t").get<double>(), 10.0);
  // The stop: the front past 7.7 − 1.25 × 1.6 = 5.7, and never within one radius (6.1) of the cap.
  const Points x = io::read_checkpoint(dir / "checkpoint.h5").positions;
  EXPECT_GT(x.col(0).maxCoeff(), 5.7);
  EXPECT_LT(x.col(0).maxCoeff(), 6.1);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace capsflow
