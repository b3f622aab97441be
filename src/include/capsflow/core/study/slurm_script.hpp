#pragma once
// The batch scripts of a Slurm study (docs/study.md shows one), written to DIR/slurm/ at every
// submission: variants.sh runs array task i as the study's variant i (the study's own command with
// --variant, variant_command.hpp); analyse.sh runs `capsflow study --analyse DIR`. The resources
// of each submission are on its sbatch line; the site's --slurm-opt are #SBATCH lines of both.
#include <string>
#include <vector>

#include "capsflow/core/study/slurm_sizing.hpp"
#include "capsflow/core/study/study_runner.hpp"

namespace capsflow::study {

// Seconds before its time limit at which a variant is sent SIGTERM: it stops with a checkpoint
// (exit 130) and the next `capsflow study` call continues it. Checkpoints take seconds.
inline constexpr int kStopBeforeLimitSeconds = 120;

struct ScriptVariant {
  std::size_t index;  // the array task id: the variant's index in the plan
  const Variant* variant;
  JobSize size;
};

std::string variants_script(const std::string& exe, const StudyOptions& o, const StudyPlan& plan,
                            const std::vector<ScriptVariant>& submitted);
std::string analysis_script(const std::string& exe, const StudyOptions& o);

// The #SBATCH options of a site option list, checked: each must be an option (starting with '-'),
// and not one capsflow sets itself (--array, --dependency, --output, --job-name, …). Throws
// std::runtime_error naming --slurm-opt.
void check_site_options(const std::vector<std::string>& options);
// Whether the site options set `name` (e.g. "--time" also matches "-t"), which then replaces
// capsflow's own value.
bool site_sets(const std::vector<std::string>& options, const std::string& long_name, const std::string& short_name);

}  // namespace capsflow::study
