// A study's variant that runs several capsules: its observables are capsule 1's, from
// summary.json's `capsules` list and the c1. columns of timeseries.csv (docs/several-capsules.md).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "capsflow/core/driver/simulation.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "capsflow/core/study/variant_folder.hpp"
#include "../driver/tiny_pair_scene.hpp"

namespace capsflow {
namespace {
namespace fs = std::filesystem;

TEST(VariantOfSeveralCapsules, TheObservablesAreCapsuleOnes) {
  const fs::path dir = fs::temp_directory_path() / ("capsflow-variant-pair-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  // Capsule 1 (below) and 2 (above the plane x2 = 0).
  RunOptions o;
  o.scene = parse_scene(test::kTinyShearScene, "pair.toml", {"layout.count=2", "layout.dx=-3", "layout.dy=1"});
  o.output_dir = dir.string();
  o.threads = 1;
  ASSERT_EQ(Simulation(o).run(), 0);
  std::ifstream f(dir / "summary.json");
  const nlohmann::json s = nlohmann::json::parse(f);
  const study::VariantResult r = study::read_variant_result(dir);
  EXPECT_EQ(r.final_values.at("D12"), s["capsules"][0]["D12"].get<double>());
  EXPECT_EQ(r.final_values.at("Le1"), s["capsules"][0]["Le"][0].get<double>());
  EXPECT_EQ(r.final_values.at("volume_drift"), s["capsules"][0]["volume_drift"].get<double>());
  ASSERT_EQ(r.times.size(), 3u) << "rows at t = 0, 0.2, 0.4";
  EXPECT_EQ(r.series.at("D12").back(), r.final_values.at("D12")) << "the last row is the final state";
  EXPECT_EQ(r.elements, 160) << "all capsules' elements";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace capsflow
