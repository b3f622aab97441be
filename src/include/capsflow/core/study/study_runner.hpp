#pragma once
// `capsflow study`: runs the variants of a StudyPlan where the scheduler says (docs/study.md),
// then writes DIR/study.json, study.csv and study.md (study_report.hpp).
//
// - local, --jobs 1 (the default): one after the other, in this process, each as an ordinary run
//   in DIR/<variant>/ (variant_run.hpp), coarse levels first; after each one a line with the key
//   results and the ETA (cost_model.hpp), and the study files rewritten;
// - local, --jobs K: K variants at once, each in a child process (local_jobs.hpp);
// - slurm: one job per variant through sbatch, and an analysis job after them (slurm_study.hpp).
//
// Resumable: a variant whose folder holds a finished run of the same scene is not run again; an
// interrupted one (summary.json says so, or only a checkpoint is there) continues from its
// checkpoint; one that stopped numerically (blow_up, solver_failure, no_progress) is reported and
// left alone — delete its folder or pass --overwrite to run it again. A folder holding a run of
// another scene is refused with one line. --overwrite runs every variant anew (each variant folder
// as `run --overwrite`: only capsflow's files are removed) and replaces the study files; nothing
// else in DIR is touched.
#include <filesystem>
#include <string>
#include <vector>

#include "capsflow/core/named_enum.hpp"
#include "capsflow/core/study/study_plan.hpp"

namespace capsflow::study {

enum class Scheduler { Local, Slurm };
inline constexpr NameTable<Scheduler, 2> kSchedulerNames{{{Scheduler::Local, "local"}, {Scheduler::Slurm, "slurm"}}};
constexpr const auto& name_table(Scheduler) { return kSchedulerNames; }

struct StudyOptions {
  std::string scene_path;  // "" = the built-in default scene
  std::vector<std::string> overrides;
  std::vector<int> levels;
  std::vector<VaryAxis> vary;
  std::filesystem::path dir = "capsflow-study";
  bool overwrite = false;
  int threads = 0;  // per variant for --jobs 1 and Slurm (0: all cores, or sized per variant); in all for --jobs K
  bool verbose = false;  // show each run's own log lines (status lines, timing table)
  double heartbeat_seconds = 60;  // otherwise: a line with the running variant's t this often
  std::string command_line;
  Scheduler scheduler = Scheduler::Local;
  int jobs = 1;                            // local: variants at once
  std::vector<std::string> slurm_options;  // --slurm-opt, e.g. "--partition=short"
  std::string variant;                     // run only this variant, study files untouched (the jobs' entry point)
};

// Exit code: 0 every variant finished (Slurm: everything submitted or finished); 3 some stopped
// numerically (the analysis uses the others); 130 interrupted by SIGINT/SIGTERM (the variant
// keeps its checkpoint: run the same command again to continue). Throws std::runtime_error (one
// line) for bad input and I/O errors.
int run_study(const StudyOptions& options);

// `capsflow study --analyse DIR`: the study recorded in DIR/study.json, analysed on whatever has
// finished; says what is missing. Exit code 0 when every variant finished, 3 when some did not
// (stopped numerically, failed, not run yet).
int analyse_study_folder(const std::filesystem::path& dir);

}  // namespace capsflow::study
