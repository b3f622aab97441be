#pragma once
// `capsflow run`: one capsule simulation from a resolved scene to an output folder
// (docs/time-integration.md §5.1–5.5, docs/scene-and-output.md §3): time loop (RK2, dt auto/fixed), health checks, steady-state detection,
// outputs (HDF5 + XDMF, timeseries.csv, summary.json), checkpoints (periodic, at the end, on
// SIGINT/SIGTERM), restart, progress lines and the per-phase timing table.
#include <string>

#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

struct RunOptions {
  Scene scene;                 // resolved; ignored on restart unless overrides were given
  std::string output_dir = "capsflow-out";
  bool overwrite = false;
  std::string restart;         // checkpoint to continue from
  std::vector<std::string> restart_overrides;  // --set applied to the checkpoint's scene
  int threads = 0;             // 0 = OpenMP default
  std::string command_line;
  double progress_interval = 2.0;  // seconds of wall time between status lines
};

// Returns the process exit code: 0 for t_end/steady, 3 for blow_up/no_progress, 130 for interrupted.
// Throws std::runtime_error (one line) for set-up errors before any step was taken.
int run_simulation(const RunOptions& options);

}  // namespace capsflow
