// What a study makes of a variant folder's summary.json: the driver's typed stop reason decides
// finished / failed / interrupted (driver/stop_reason.hpp), whatever detail the reason carries, and
// the study writes the reason back exactly as summary.json spells it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "capsflow/core/study/variant_folder.hpp"

using namespace capsflow;
namespace fs = std::filesystem;

namespace {

struct Folder {
  fs::path path = fs::temp_directory_path() / ("capsflow-variant-folder-" + std::to_string(::getpid()));
  Folder() {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~Folder() { fs::remove_all(path); }
  // A summary.json with every key the study reads, and a timeseries.csv of two rows.
  // A channel run (channel = true) adds its summary keys and columns.
  void write_run(const nlohmann::json& stop_reason, bool channel = false) const {
    nlohmann::json s = {{"t", 0.5},       {"elements", 80},  {"nodes", 42},  {"wall_seconds", 1.5}, {"rhs_evaluations", 10},
                        {"D12", 0.1},     {"D13", -0.2},     {"D23", 0.0},   {"area", 1.0},         {"volume_drift", 1e-9},
                        {"L", {1, 2, 3}}, {"Le", {1, 2, 3}}, {"scene", {}},
                        {"timing", {{"seconds_per_evaluation", 0.1}, {"rhs_evaluations", 10}, {"phases", {{"bie_far", 0.5}}}}}};
    if (!stop_reason.is_null()) s["stop_reason"] = stop_reason;
    std::vector<std::string> names = study::observable_names();
    if (channel) {
      s["velocity_ratio"] = 1.25, s["pressure_drop"] = 7.5, s["channel"] = {{"shape", "tube"}};
      names.insert(names.end(), {"velocity_ratio", "pressure_drop"});
    }
    std::ofstream(path / "summary.json") << s.dump(2);
    std::ofstream csv(path / "timeseries.csv");
    csv << "t";
    for (const std::string& n : names) csv << "," << n;
    for (double t : {0.0, 0.5}) {
      csv << "\n" << t;
      for (std::size_t i = 0; i < names.size(); ++i) csv << ",0.5";
    }
    csv << "\n";
  }
};

}  // namespace

TEST(VariantFolder, TheStopReasonsKindDecidesTheFoldersState) {
  const Folder f;
  EXPECT_EQ(study::inspect_variant_folder(f.path), study::FolderState::Empty);
  const std::pair<const char*, study::FolderState> cases[] = {
      {"t_end", study::FolderState::Finished},
      {"steady", study::FolderState::Finished},
      {"outlet", study::FolderState::Finished},
      {"interrupted", study::FolderState::Interrupted},
      {"blow_up", study::FolderState::Failed},
      {"no_progress: 20 rejected steps in a row", study::FolderState::Failed},
      {"solver_failure: rotation Newton: no convergence in 50 iterations", study::FolderState::Failed},
      {"mesh_scale_buckling", study::FolderState::Failed},  // a time.stop_on health condition
  };
  for (const auto& [reason, state] : cases) {
    f.write_run(reason);
    EXPECT_EQ(study::inspect_variant_folder(f.path), state) << reason;
    // summary.json's string comes back exactly (study.json and the study's lines repeat it).
    EXPECT_EQ(study::read_variant_result(f.path).stop.to_string(), reason);
  }
}

TEST(VariantFolder, AStopReasonThisCapsflowDoesNotWriteIsAnErrorNamingTheFile) {
  const Folder f;
  for (const nlohmann::json& bad : {nlohmann::json("t_ended"), nlohmann::json(3), nlohmann::json()}) {
    f.write_run(bad);
    try {
      study::inspect_variant_folder(f.path);
      ADD_FAILURE() << bad.dump() << " was accepted";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find((f.path / "summary.json").string()), std::string::npos) << what;
      EXPECT_NE(what.find("is not one this capsflow writes"), std::string::npos) << what;
    }
    EXPECT_THROW(study::read_variant_result(f.path), std::runtime_error) << bad.dump();
  }
}

TEST(VariantFolder, AChannelRunAddsItsSpeedAndPressureDropToTheObservables) {
  const Folder f;
  f.write_run("t_end", true);
  const study::VariantResult r = study::read_variant_result(f.path);
  EXPECT_EQ(r.final_values.at("velocity_ratio"), 1.25);  // exact: read back from the JSON
  EXPECT_EQ(r.final_values.at("pressure_drop"), 7.5);
  EXPECT_EQ(r.series.at("velocity_ratio"), (std::vector<double>{0.5, 0.5}));
  f.write_run("t_end", false);
  EXPECT_EQ(study::read_variant_result(f.path).series.count("velocity_ratio"), 0u);  // not a channel run
}
