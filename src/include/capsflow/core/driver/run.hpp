#pragma once
// `capsflow run`: one capsule simulation from a resolved scene to an output folder
// (docs/time-integration.md §5, docs/scene-and-output.md §3): the time loop (driver/simulation.hpp),
// health checks, steady-state detection, outputs (HDF5 + XDMF, timeseries.csv, summary.json),
// checkpoints (periodic, at the end, on SIGINT/SIGTERM), restart, progress lines and the
// per-phase timing table.
#include <functional>
#include <string>
#include <vector>

#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

// What the status line shows, for a caller's progress callback.
struct RunProgress {
  long step = 0;
  double t = 0, t_end = 0, dt = 0;
  long rhs_evaluations = 0;  // the whole run, restarts included
  double wall_seconds = 0;   // the whole run, restarts included
  double eta_seconds = 0;    // NaN until this segment has advanced
  double volume_drift = 0;   // V/V0 − 1
  double steady_measure = 0; // the steady-state measure (NaN in the first time unit)
  std::string health;        // the health monitors' status ("ok" or the active conditions)
};

struct RunOptions {
  Scene scene;                 // resolved; ignored on restart unless overrides were given
  std::string output_dir = "capsflow-out";
  bool overwrite = false;
  std::string restart;         // checkpoint to continue from
  std::vector<std::string> restart_overrides;  // --set applied to the checkpoint's scene
  // A restart from a checkpoint at time.t_end is accepted and only finishes the run (summary.json
  // from the checkpoint's state, no step): a run killed after its last checkpoint and before its
  // summary.json. Otherwise such a restart is refused (nothing to continue). The study sets it.
  bool finish_at_t_end = false;
  int threads = 0;             // 0 = OpenMP default
  std::string command_line;
  double progress_interval = 2.0;  // seconds of wall time between status lines
  std::function<void(const RunProgress&)> on_progress;  // called with each status line (may be empty)
};

// Returns the process exit code (StopReason::exit_code, driver/stop_reason.hpp): 0 for t_end or
// steady, 3 for a stop whose state is not to be trusted, 130 for interrupted.
// Throws std::runtime_error (one line) for set-up errors before any step was taken.
int run_simulation(const RunOptions& options);

}  // namespace capsflow
