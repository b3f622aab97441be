#pragma once
// What a study variant's folder holds (an ordinary run folder, docs/scene-and-output.md §3), and
// the results the analysis reads from it: the final state and cost from summary.json, the
// observables at every output time from timeseries.csv.
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capsflow/core/driver/stop_reason.hpp"

namespace capsflow::study {

enum class FolderState {
  Empty,        // nothing there yet (or no folder)
  Finished,     // summary.json with a stop reason that completes the run (t_end, steady)
  Failed,       // summary.json with a numerical stop (blow_up, solver_failure, no_progress, a stop_on condition)
  Interrupted,  // summary.json says interrupted, or no summary but a checkpoint: continue from it
  Unfinished,   // run files without summary or checkpoint (killed before its first checkpoint): start again
};

// Throws std::runtime_error naming the file when summary.json cannot be read or its stop_reason is
// not one this capsflow writes (driver/stop_reason.hpp).
FolderState inspect_variant_folder(const std::filesystem::path& dir);

// The observables of the analysis: names of timeseries.csv columns (L and Le of summary.json
// become L1..L3, Le1..Le3).
const std::vector<std::string>& observable_names();
// A channel run's further observables (docs/channel.md §5): columns and summary.json keys.
const std::vector<std::string>& channel_observable_names();

struct VariantResult {
  nlohmann::json summary;  // summary.json as written
  StopReason stop{StopKind::TEnd};  // its stop_reason; to_string() gives it back as written
  double t_final = 0;
  long elements = 0, nodes = 0;
  double wall_seconds = 0;     // whole run, restarted segments included
  long rhs_evaluations = 0;    // whole run
  double seconds_per_evaluation = 0;  // of the last segment (its timing table)
  std::map<std::string, double> seconds_per_evaluation_by_phase;  // last segment
  double peak_rss_mb = 0;      // 0 when the summary predates the key
  std::map<std::string, double> final_values;        // observable → value at the end (a channel's too)
  std::vector<double> times;                         // output times of timeseries.csv
  std::map<std::string, std::vector<double>> series;  // observable → value per output time
};

// Reads DIR/summary.json and DIR/timeseries.csv. Throws std::runtime_error naming the file.
VariantResult read_variant_result(const std::filesystem::path& dir);

// Throws std::runtime_error ("cannot read 'P': it is a FIFO, not a regular file …") when `p`
// exists and is not a regular file: a study file (study.json, a variant's summary.json or
// timeseries.csv, the job record) that is a FIFO or a device would block its reader for ever
// (io/input_file.hpp). A missing file passes: its reader says what that means.
void require_regular_file(const std::filesystem::path& p);

}  // namespace capsflow::study
