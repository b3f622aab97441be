// The large-deformation shear benchmark (label slow, 77 s on one core):
// scenes/sphere_nh_shear_ca06.toml (NH membrane, Ca_s = 0.6, t = 8) converges in the mesh.
// No capsflow value is used as an expected value: the assertions are convergence properties.
// Measured (docs/large-deformation-shear.md §6): D12(8) = 0.5121, 0.5200, 0.5222 at 320, 1280,
// 5120 elements (differences 7.9e-3, 2.2e-3: observed order 1.85); 20 480 curved elements give
// 0.5227, the Richardson limit within 2e-4. Runtime 77 s (one thread).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "capsflow/core/driver/run.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "temp_dir.hpp"

using namespace capsflow;

namespace {
double d12_at_t_end(int level) {
  const io::testing::TempDir dir;  // the runs write only here
  const std::string scene = std::string(CAPSFLOW_SOURCE_DIR) + "/scenes/sphere_nh_shear_ca06.toml";
  RunOptions o;
  o.scene = load_scene(scene, {"mesh.level=" + std::to_string(level), "output.every=1.0", "output.fields=[]",
                               "output.checkpoint_every=0"});
  o.output_dir = (dir.path() / ("shear_convergence_l" + std::to_string(level))).string();
  o.overwrite = true;
  o.threads = 1;
  o.progress_interval = 1e9;
  EXPECT_EQ(run_simulation(o), 0) << level;
  std::ifstream f(std::filesystem::path(o.output_dir) / "summary.json");
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_NEAR(j["t"].get<double>(), 8.0, 1e-12);
  return j["D12"].get<double>();
}
}  // namespace

TEST(ShearConvergence, NeoHookeanSphereAtCa06ConvergesAtSecondOrder) {
  const double d2 = d12_at_t_end(2), d3 = d12_at_t_end(3), d4 = d12_at_t_end(4);
  std::printf("D12(8): level 2 %.5f  level 3 %.5f  level 4 %.5f\n", d2, d3, d4);
  // Monotone approach (from below: coarse meshes under-predict the deformation).
  EXPECT_LT(d2, d3);
  EXPECT_LT(d3, d4);
  // Observed order log2((d3 - d2)/(d4 - d3)): 2 for the O(h^2) P1 discretisation; measured 1.85.
  const double order = std::log2((d3 - d2) / (d4 - d3));
  EXPECT_GT(order, 1.5);
  // Richardson remainder of the 5120-element value, (d4 - d3)/(2^p - 1) with the observed p:
  // measured 8e-4; 2e-3 would already be a 0.4 % discretisation error at this deformation.
  EXPECT_LT((d4 - d3) / (std::pow(2.0, order) - 1.0), 2e-3);
}
