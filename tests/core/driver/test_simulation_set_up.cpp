// Simulation::set_up and a stop request: a request made before the set-up has written the run's
// first state ends it with SetUpInterrupted and leaves nothing behind (no folder, no lock); the
// command line's SIGINT during the set-up is tested end to end in tests/app/test_cli.cpp.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "capsflow/core/driver/simulation.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow {
namespace {
namespace fs = std::filesystem;

TEST(SimulationSetUp, AStopRequestedBeforeTheFirstStateEndsTheSetUpAndLeavesNoFolder) {
  const fs::path dir = fs::temp_directory_path() / ("capsflow-set-up-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  RunOptions o;
  o.scene = parse_scene(default_scene_toml(), "<built-in default>", {"mesh.level=1", "time.t_end=0.01"});
  o.output_dir = (dir / "out").string();
  o.threads = 1;
  Simulation sim(o);
  sim.request_stop(SIGINT);
  try {
    sim.set_up();
    FAIL() << "the set-up ran to its end";
  } catch (const SetUpInterrupted& e) {
    EXPECT_NE(std::string(e.what()).find("signal 2 received during the set-up: stopped before the first step"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "out"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace capsflow
