// `capsflow run [SCENE] ...`: resolve the scene (or take the checkpoint's) and run it.
#include <spdlog/spdlog.h>

#include <string>

#include "capsflow/core/driver/run.hpp"
#include "capsflow/core/driver/thread_count.hpp"
#include "commands.hpp"

namespace capsflow::app {

int run_command(const RunCommandOptions& o) {
  check_thread_count(o.threads, "--threads " + std::to_string(o.threads));  // before any folder is locked
  RunOptions r;
  r.output_dir = o.output_dir;
  r.overwrite = o.overwrite;
  r.threads = o.threads;
  r.command_line = o.command_line;
  if (!o.restart.empty()) {
    if (o.overwrite)
      throw std::runtime_error("--restart cannot be combined with --overwrite: it continues in the run's own folder, or starts a new or empty one (-o NEW)");
    if (!o.scene_path.empty()) throw std::runtime_error("--restart takes the scene from the checkpoint; use --set to change keys");
    r.restart = o.restart;
    r.restart_overrides = o.overrides;
    if (o.output_dir_given == false) r.output_dir.clear();  // continue in the checkpoint's folder
  } else {
    r.scene = o.scene_path.empty() ? parse_scene(default_scene_toml(), "<built-in default>", o.overrides)
                                   : load_scene(o.scene_path, o.overrides);
  }
  return run_simulation(r);
}

}  // namespace capsflow::app
