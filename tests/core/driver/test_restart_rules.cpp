// Restart rules: which folder a restart may write into, and which --set keys it may change.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "capsflow/core/driver/restart_rules.hpp"
#include "capsflow/core/io/h5.hpp"
#include "capsflow/core/io/results_writer.hpp"
#include "capsflow/core/io/run_identity.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"

using namespace capsflow;
namespace fs = std::filesystem;

namespace {

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("capsflow-restart-" + std::to_string(::getpid()) + "-" +
                                               ::testing::UnitTest::GetInstance()->current_test_info()->name());
  TempDir() {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

const std::vector<std::string> kTiny = {"mesh.level=1", "wall.model=membrane", "wall.law=nh", "flow.ca_s=0.2"};

// A checkpoint of run `run_id` at t = 0.5 of the tiny scene, and a run folder `dir` holding run
// `folder_run_id` with the mesh of `folder_level`.
io::CheckpointState checkpoint(const std::string& run_id) {
  const Scene s = parse_scene(default_scene_toml(), "d", kTiny);
  const SurfaceMesh m = make_reference_mesh(s.mesh);
  io::CheckpointState ck;
  ck.t = 0.5;
  ck.dt = 1e-3;
  ck.positions = ck.reference_positions = m.vertices;
  ck.triangles = m.triangles;
  ck.scene_toml = to_toml(s);
  ck.run_id = run_id;
  return ck;
}

void make_run_folder(const fs::path& dir, const std::string& run_id, int level = 1) {
  std::vector<std::string> o = kTiny;
  o.push_back("mesh.level=" + std::to_string(level));
  const SurfaceMesh m = make_reference_mesh(parse_scene(default_scene_toml(), "d", o).mesh);
  fs::create_directories(dir);
  nlohmann::json meta = {{"command_line", "test"}};
  if (!run_id.empty()) meta["run_id"] = run_id;
  io::ResultsWriter w(dir, m, meta);
  w.write_step(0.0, m.vertices);
}

std::string refusal(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(RestartRules, TheCheckpointsOwnRunContinuesInPlace) {
  TempDir d;
  make_run_folder(d.path / "A", "run-a");
  const RestartPlan p = plan_restart(checkpoint("run-a"), d.path / "A" / "checkpoint.h5", {"time.t_end=1"}, "");
  EXPECT_EQ(p.folder, d.path / "A");
  EXPECT_FALSE(p.new_folder);
  EXPECT_EQ(p.run_id, "run-a");
  EXPECT_EQ(p.scene.time.t_end, 1.0);  // exact: parsed from "1"
}

TEST(RestartRules, AFolderOfAnotherRunIsRefused) {
  // `--restart A/checkpoint.h5 -o B` with B a different, finished run: B's later steps and CSV
  // rows were deleted, its checkpoint and summary replaced, with exit 0.
  TempDir d;
  make_run_folder(d.path / "B", "run-b");
  const std::string e = refusal([&] { plan_restart(checkpoint("run-a"), d.path / "A" / "checkpoint.h5", {"time.t_end=1"}, (d.path / "B").string()); });
  EXPECT_NE(e.find("belongs to another run (run id run-b"), std::string::npos) << e;
  EXPECT_NE(e.find("-o NEW"), std::string::npos) << e;
  // Same run id but another mesh (162 vs 42 nodes: "write_step: positions have 162 rows"): refused too.
  make_run_folder(d.path / "C", "run-a", 2);
  const std::string m = refusal([&] { plan_restart(checkpoint("run-a"), d.path / "A" / "checkpoint.h5", {"time.t_end=1"}, (d.path / "C").string()); });
  EXPECT_NE(m.find("its mesh differs from the checkpoint's 80 elements"), std::string::npos) << m;
  // A non-empty folder that is no run folder.
  fs::create_directories(d.path / "D");
  std::ofstream(d.path / "D" / "notes.txt") << "x";
  const std::string n = refusal([&] { plan_restart(checkpoint("run-a"), d.path / "A" / "checkpoint.h5", {"time.t_end=1"}, (d.path / "D").string()); });
  EXPECT_NE(n.find("holds no run.h5"), std::string::npos) << n;
}

TEST(RestartRules, ANewOrEmptyFolderStartsANewRunFolder) {
  // `--restart` could not write into a new or empty folder ("it does not exist").
  TempDir d;
  fs::create_directories(d.path / "empty");
  for (const fs::path& out : {d.path / "new" / "sub", d.path / "empty"}) {
    const RestartPlan p = plan_restart(checkpoint("run-a"), d.path / "A" / "checkpoint.h5", {"time.t_end=1"}, out.string());
    EXPECT_TRUE(p.new_folder);
    EXPECT_EQ(p.folder, out);
    EXPECT_EQ(p.parent_run_id, "run-a");
    EXPECT_NE(p.run_id, "run-a");  // a new folder is a new run
    EXPECT_EQ(p.run_id.size(), 32u);
  }
  EXPECT_FALSE(fs::exists(d.path / "new"));  // planning writes nothing
}

TEST(RestartRules, FilesFromBeforeRunIdsContinueOnlyInTheirOwnFolder) {
  TempDir d;
  make_run_folder(d.path / "A", "");
  make_run_folder(d.path / "B", "");
  const RestartPlan p = plan_restart(checkpoint(""), d.path / "A" / "checkpoint.h5", {"time.t_end=1"}, "");
  EXPECT_FALSE(p.new_folder);
  EXPECT_EQ(p.run_id.size(), 32u);  // a new id, recorded from now on
  const std::string e = refusal([&] { plan_restart(checkpoint(""), d.path / "A" / "checkpoint.h5", {"time.t_end=1"}, (d.path / "B").string()); });
  EXPECT_NE(e.find("cannot tell whether"), std::string::npos) << e;
}

TEST(RestartRules, MeshAndWallModelOverridesAreRefusedNotIgnored) {
  // --set mesh.level on restart was ignored but recorded (summary: level 3 next to 320
  // elements); wall.model = membrane on a GSMB checkpoint switched the model silently.
  TempDir d;
  make_run_folder(d.path / "A", "run-a");
  const auto ck = checkpoint("run-a");
  const fs::path path = d.path / "A" / "checkpoint.h5";
  for (const std::string key : {"mesh.level=3", "mesh.shape=sphere", "mesh.file=x.off", "mesh.aspect=2", "mesh.axis=1",
                                "mesh.base=octahedron"}) {
    const std::string e = refusal([&] { plan_restart(ck, path, {key, "time.t_end=1"}, ""); });
    EXPECT_EQ(e.rfind("--set " + key.substr(0, key.find('=')) + ": a restarted run keeps the mesh of its checkpoint (80 elements)", 0), 0u) << e;
  }
  const std::string w = refusal([&] { plan_restart(ck, path, {"wall.model=gsmb", "time.t_end=1"}, ""); });
  EXPECT_NE(w.find("--set wall.model: the checkpoint holds the state of a membrane wall"), std::string::npos) << w;
  const std::string t = refusal([&] { plan_restart(ck, path, {"time.t_end=0.5"}, ""); });
  EXPECT_NE(t.find("time.t_end = 0.5 is not after the checkpoint time t = 0.5"), std::string::npos) << t;
  // The same value as stored, and every other key, are applied.
  const RestartPlan p = plan_restart(ck, path, {"mesh.level=1", "wall.law=skalak", "flow.type=quiescent",
                                                "output.every=0.25", "fluid.backend=direct", "time.t_end=2"}, "");
  EXPECT_EQ(p.scene.wall.law, shell::LawKind::Skalak);
  EXPECT_EQ(p.scene.flow.type, FlowType::Quiescent);
  EXPECT_EQ(p.scene.output.every, 0.25);
}

TEST(RestartRules, AChangedIntervalRestartsItsIndexFromTheCheckpointTime) {
  // output.every 0.1 → 0.25 at t = 0.5 with stored next_output = 6 (t = 0.6): the old index
  // meant t = 1.5 next, skipping outputs (or, the other way round, a time before t: a negative step).
  EXPECT_EQ(restart_index(6, 0.1, 0.25, 0.5), 3);   // 0.75
  EXPECT_EQ(restart_index(6, 0.1, 0.1, 0.5), 6);    // unchanged: kept for a bit-for-bit continuation
  EXPECT_EQ(restart_index(2, 0.5, 0.05, 0.5), 11);  // 0.55
}

TEST(RestartRules, SwitchingTheFarFieldCheckIsRefusedInPlaceButNotInANewFolder) {
  // fluid.verify_every adds two timeseries.csv columns: switching it in the run's own folder would
  // make the next row's columns differ from the header mid-run.
  TempDir d;
  make_run_folder(d.path / "A", "run-a");
  const std::string e =
      refusal([&] { plan_restart(checkpoint("run-a"), d.path / "A" / "checkpoint.h5", {"time.t_end=1", "fluid.verify_every=5"}, ""); });
  EXPECT_NE(e.find("--set fluid.verify_every"), std::string::npos) << e;
  EXPECT_NE(e.find("-o NEW"), std::string::npos) << e;
  const RestartPlan p = plan_restart(checkpoint("run-a"), d.path / "A" / "checkpoint.h5", {"time.t_end=1", "fluid.verify_every=5"},
                                     (d.path / "new").string());
  EXPECT_TRUE(p.new_folder);
  EXPECT_EQ(p.scene.fluid.verify_every, 5);
}

// fluid.viscosity_ratio ≠ 1 adds the gmres_per_eval column: switching between λ = 1 and λ ≠ 1 in the
// run's own folder is refused (as fluid.verify_every), into a new folder it is not; λ ≠ 1 → another
// λ ≠ 1 keeps the columns.
TEST(RestartRules, SwitchingToAViscosityRatioIsRefusedInPlaceButNotInANewFolder) {
  TempDir d;
  make_run_folder(d.path / "A", "run-a");
  const std::string e = refusal(
      [&] { plan_restart(checkpoint("run-a"), d.path / "A" / "checkpoint.h5", {"time.t_end=1", "fluid.viscosity_ratio=5"}, ""); });
  EXPECT_NE(e.find("--set fluid.viscosity_ratio"), std::string::npos) << e;
  EXPECT_NE(e.find("-o NEW"), std::string::npos) << e;
  const RestartPlan p = plan_restart(checkpoint("run-a"), d.path / "A" / "checkpoint.h5",
                                     {"time.t_end=1", "fluid.viscosity_ratio=5"}, (d.path / "new").string());
  EXPECT_EQ(p.scene.fluid.viscosity_ratio, 5.0);
}

// A run folder whose timeseries.csv predates the flow-plane columns cannot take today's rows in place.
TEST(RestartRules, AFolderWithoutTheFlowPlaneColumnsIsRefusedInPlace) {
  TempDir d;
  make_run_folder(d.path / "A", "run-a");
  { std::ofstream(d.path / "A" / "timeseries.csv") << "t,step,dt,D12\n0,0,0,0\n"; }
  const std::string e = refusal([&] { plan_restart(checkpoint("run-a"), d.path / "A" / "checkpoint.h5", {"time.t_end=1"}, ""); });
  EXPECT_NE(e.find("without the columns D_flow, theta and tank_treading"), std::string::npos) << e;
  { std::ofstream(d.path / "A" / "timeseries.csv") << "t,step,dt,D12,D_flow,theta,tank_treading\n0,0,0,0,0,0,\n"; }
  EXPECT_EQ(refusal([&] { plan_restart(checkpoint("run-a"), d.path / "A" / "checkpoint.h5", {"time.t_end=1"}, ""); }), "");
}
