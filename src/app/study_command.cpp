// `capsflow study [SCENE] -o DIR --levels 3,4,5 [--vary key=v1,v2]... [--set key=value]...`:
// parse the levels and vary axes, then hand over to study/study_runner.
#include "capsflow/core/study/study_runner.hpp"
#include "commands.hpp"

namespace capsflow::app {

int study_command(const StudyCommandOptions& o) {
  study::StudyOptions s;
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
