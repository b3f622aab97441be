#pragma once
// One variant of a study run in this process as an ordinary run in its folder (driver/run.hpp):
// from the start (only capsflow's files in the folder are replaced) or, when it was interrupted,
// from its checkpoint. Its own info lines are hidden unless verbose; a heartbeat line then gives
// the time it has reached every `heartbeat_seconds`. The progress lines of a study, shared by
// every scheduler, are here too.
#include <filesystem>
#include <string>

#include "capsflow/core/study/study_plan.hpp"
#include "capsflow/core/study/variant_folder.hpp"

namespace capsflow::study {

struct VariantRunOptions {
  std::string tag;  // prefix of its lines, e.g. "study [3/6] L2"
  int threads = 0;
  bool verbose = false;
  double heartbeat_seconds = 60;
  std::string command_line;  // the study's, recorded in the run's metadata with the variant's name
};

// The run's exit code (0, 3 numerical stop, 130 interrupted). Throws std::runtime_error (one
// line) for bad input and I/O errors, as run_simulation does.
int run_variant(const Variant& v, const std::filesystem::path& folder, bool resume, const VariantRunOptions& o);

// "1m05s", "2h03m"; "?" for a negative or non-finite time.
std::string hms(double seconds);
// "t_end at t = 0.25, 1280 elements, 96 evaluations in 0m01s (…), D12 … , peak 20 MB".
std::string result_line(const VariantResult& r);

}  // namespace capsflow::study
