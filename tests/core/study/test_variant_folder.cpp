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
  void write_run(const nlohmann::json& stop_reason) const {
    nlohmann::json s = {{"t", 0.5},       {"elements", 80},  {"nodes", 42},  {"wall_seconds", 1.5}, {"rhs_evaluations", 10},
                        {"D12", 0.1},     {"D13", -0.2},     {"D23", 0.0},   {"area", 1.0},         {"volume_drift", 1e-9},
                        {"L", {1, 2, 3}}, {"Le", {1, 2, 3}}, {"scene", {}},
                        {"timing", {{"seconds_per_evaluation", 0.1}, {"rhs_evaluations", 10}, {"phases", {{"bie_far", 0.5}}}}}};
    if (!stop_reason.is_null()) s["stop_reason"] = stop_reason;
    std::ofstream(path / "summary.json") << s.dump(2);
    std::ofstream csv(path / "timeseries.csv");
    csv << "t";
    for (const std::string& n : study::observable_names()) csv << "," << n;
    for (double t : {0.0, 0.5}) {
      csv << "\n" << t;
      for (std::size_t i = 0; i < study::observable_names().size(); ++i) csv << ",0.5";
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
