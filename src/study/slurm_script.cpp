#include "capsflow/core/study/slurm_script.hpp"

#include <fmt/core.h>

#include <filesystem>
#include <stdexcept>

#include "capsflow/core/io/version.hpp"
#include "capsflow/core/study/slurm_records.hpp"
#include "capsflow/core/study/variant_command.hpp"

namespace capsflow::study {
namespace fs = std::filesystem;

namespace {

std::string site_lines(const std::vector<std::string>& options) {
  std::string out;
  for (const std::string& s : options) out += "#SBATCH " + s + "\n";
  return out;
}

std::string joined(const std::vector<std::string>& argv) {
  std::string out;
  for (const std::string& a : argv) out += (out.empty() ? "" : " ") + shell_quote(a);
  return out;
}

bool matches(const std::string& option, const std::string& long_name, const std::string& short_name) {
  if (option == long_name || option.rfind(long_name + "=", 0) == 0) return true;
  return !short_name.empty() && option.rfind(short_name, 0) == 0;
}

}  // namespace

std::string variants_script(const std::string& exe, const StudyOptions& o, const StudyPlan& plan,
                            const std::vector<ScriptVariant>& submitted) {
  const fs::path dir = fs::absolute(o.dir).lexically_normal();
  std::string s = "#!/bin/bash\n";
  s += fmt::format("# capsflow study {}: array task i runs variant i (written by capsflow {} at each submission).\n", dir.string(),
                   version_string());
  s += "# Resources are on each submission's sbatch line (slurm/jobs.json), sized from the study's cost model:\n";
  s += "#   task  variant                     elements  threads  memory    time limit  (predicted)\n";
  for (const ScriptVariant& v : submitted)
    s += fmt::format("#   {:<5} {:<27} {:<9} {:<8} {:<9} {:<11} ({:.0f} s{})\n", v.index, v.variant->name, v.variant->elements,
                     v.size.threads, std::to_string(v.size.memory_mb) + "M", std::to_string(v.size.minutes) + " min",
                     v.size.predicted_seconds, v.size.fitted ? ", fitted" : ", reference");
  s += "#SBATCH --job-name=capsflow-variant\n";
  s += fmt::format("#SBATCH --output={}/{}/variant-%A_%a.out\n", dir.string(), kSlurmFolder);
  s += fmt::format("#SBATCH --signal=B:TERM@{}\n", kStopBeforeLimitSeconds);
  s += site_lines(o.slurm_options);
  s += "set -u\nvariants=(";
  for (std::size_t i = 0; i < plan.variants.size(); ++i) s += (i ? " " : "") + shell_quote(plan.variants[i].name);
  s += ")\n";
  s += "# The study's own command, for one variant: it runs the variant, or continues it from its checkpoint.\n";
  s += "exec " + joined(variant_command(exe, o, "", 0)) +
       " --variant \"${variants[$SLURM_ARRAY_TASK_ID]}\" --threads \"${SLURM_CPUS_PER_TASK:-1}\"\n";
  return s;
}

std::string analysis_script(const std::string& exe, const StudyOptions& o) {
  const fs::path dir = fs::absolute(o.dir).lexically_normal();
  std::string s = "#!/bin/bash\n";
  s += fmt::format("# capsflow study {}: the analysis, after the variant jobs whatever their outcome (written by capsflow {}).\n",
                   dir.string(), version_string());
  s += "#SBATCH --job-name=capsflow-analyse\n";
  s += fmt::format("#SBATCH --output={}/{}/analyse-%j.out\n", dir.string(), kSlurmFolder);
  s += "#SBATCH --cpus-per-task=1\n#SBATCH --mem=1000M\n#SBATCH --time=10\n";
  s += site_lines(o.slurm_options);
  s += "exec " + joined({exe, "study", "--analyse", dir.string()}) + "\n";
  return s;
}

void check_site_options(const std::vector<std::string>& options) {
  struct Owned {
    const char *long_name, *short_name, *why;
  };
  const Owned owned[] = {{"--array", "-a", "one array task per variant"},
                         {"--dependency", "-d", "the analysis waits for the variants"},
                         {"--output", "-o", "logs go to DIR/slurm/"},
                         {"--error", "-e", "logs go to DIR/slurm/"},
                         {"--job-name", "-J", "the job names"},
                         {"--parsable", "", "reading the job id"},
                         {"--test-only", "", "checking the submission first"},
                         {"--wrap", "", "the batch scripts"},
                         {"--signal", "", "stopping with a checkpoint before the time limit"}};
  for (const std::string& opt : options) {
    if (opt.size() < 2 || opt[0] != '-' || opt.find('\n') != std::string::npos)
      throw std::runtime_error("--slurm-opt '" + opt + "': expected an sbatch option such as --partition=short");
    for (const Owned& w : owned)
      if (matches(opt, w.long_name, w.short_name))
        throw std::runtime_error("--slurm-opt " + opt + ": capsflow sets " + w.long_name + " itself (" + w.why + ")");
  }
}

bool site_sets(const std::vector<std::string>& options, const std::string& long_name, const std::string& short_name) {
  for (const std::string& opt : options)
    if (matches(opt, long_name, short_name)) return true;
  return false;
}

}  // namespace capsflow::study
