// `capsflow study [SCENE] -o DIR --levels 3,4,5 [--vary key=v1,v2]... [--set key=value]... [--scheduler …]`
// and `capsflow study --analyse DIR`: parse the levels, vary axes and scheduler, then hand over to
// study/study_runner.
#include <stdexcept>

#include "capsflow/core/driver/thread_count.hpp"
#include "capsflow/core/study/study_runner.hpp"
#include "commands.hpp"

namespace capsflow::app {

int study_command(const StudyCommandOptions& o) {
  if (!o.analyse.empty()) return study::analyse_study_folder(o.analyse);
  study::StudyOptions s;
  const auto scheduler = from_string<study::Scheduler>(o.scheduler);
  if (!scheduler) throw std::runtime_error("--scheduler " + o.scheduler + ": must be one of " + name_list<study::Scheduler>());
  s.scheduler = *scheduler;
  // The threads run here (one variant, or --jobs dividing them), before the study folder is
  // locked; a Slurm job checks its own on its node (it runs --variant).
  if (s.scheduler == study::Scheduler::Local || !o.variant.empty())
    check_thread_count(o.threads, "--threads " + std::to_string(o.threads));
  s.jobs = o.jobs;
  s.slurm_options = o.slurm_options;
  s.variant = o.variant;
  s.scene_path = o.scene_path;
  s.overrides = o.overrides;
  s.levels = study::parse_levels(o.levels);
  for (const std::string& v : o.vary) s.vary.push_back(study::parse_vary(v));
  s.dir = o.output_dir;
  s.overwrite = o.overwrite;
  s.threads = o.threads;
  s.verbose = o.verbose;
  s.command_line = o.command_line;
  return study::run_study(s);
}

}  // namespace capsflow::app
