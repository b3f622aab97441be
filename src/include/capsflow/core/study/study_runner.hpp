#pragma once
// `capsflow study`: runs the variants of a StudyPlan one after the other, in this process, each
// as an ordinary run in DIR/<variant>/ (driver/run.hpp), coarse levels first; after each one it
// prints a line with the key results and the ETA (cost_model.hpp) and rewrites DIR/study.json,
// study.csv and study.md (study_report.hpp).
//
// Resumable: a variant whose folder holds a finished run of the same scene is not run again; an
// interrupted one (summary.json says so, or only a checkpoint is there) continues from its
// checkpoint (--restart); one that stopped numerically (blow_up, solver_failure, no_progress) is
// reported and left alone — delete its folder or pass --overwrite to run it again. A folder
// holding a run of another scene is refused with one line. --overwrite runs every variant anew
// (each variant folder as `run --overwrite`: only capsflow's files are removed) and replaces the
// study files; nothing else in DIR is touched.
#include <filesystem>
#include <string>
#include <vector>

#include "capsflow/core/study/study_plan.hpp"

namespace capsflow::study {

struct StudyOptions {
  std::string scene_path;  // "" = the built-in default scene
  std::vector<std::string> overrides;
  std::vector<int> levels;
  std::vector<VaryAxis> vary;
  std::filesystem::path dir = "capsflow-study";
  bool overwrite = false;
  int threads = 0;
  bool verbose = false;  // show each run's own log lines (status lines, timing table)
  double heartbeat_seconds = 60;  // otherwise: a line with the running variant's t this often
  std::string command_line;
};

// Exit code: 0 every variant finished; 3 some stopped numerically (the analysis uses the
// others); 130 interrupted by SIGINT/SIGTERM (the variant keeps its checkpoint: run the same
// command again to continue). Throws std::runtime_error (one line) for bad input and I/O errors.
int run_study(const StudyOptions& options);

}  // namespace capsflow::study
