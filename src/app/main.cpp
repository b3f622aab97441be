// capsflow command line (docs/scene-and-output.md §1): thin — parse, build, run.
//   capsflow run [SCENE.toml] [--set key=value]... [-o DIR] [--overwrite] [--restart CKPT] [--threads N]
//   capsflow info [SCENE.toml] [--set key=value]...
//   capsflow study [SCENE.toml] [-o DIR] [--levels 3,4,5] [--vary key=v1,v2]... [--set key=value]... [--overwrite] [--threads N]
//                  [--scheduler local|slurm] [--jobs K] [--slurm-opt OPT]...
//   capsflow study --analyse DIR
//   capsflow --version
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>
#include <spdlog/cfg/env.h>

#include <climits>
#include <csignal>
#include <cstdlib>
#include <exception>
#include <new>
#include <unistd.h>

#include "capsflow/core/io/version.hpp"
#include "commands.hpp"

// OpenMP threads that spin at barriers collapse when the cores are shared with other processes
// (the rotation and mass solves have tens of barriers per stage: measured 0.4 s instead of 1 ms
// per load recovery on a loaded 2-core machine). libgomp reads OMP_WAIT_POLICY once at start-up,
// so unless the user chose a policy, re-execute once with the passive (sleeping) one.
// The executable is re-executed by its real path: exec'ing "/proc/self/exe" itself names the
// process "exe" in ps and top.
void prefer_passive_openmp_wait(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") || std::getenv("CAPSFLOW_NO_REEXEC")) return;
  setenv("OMP_WAIT_POLICY", "passive", 0);
  setenv("CAPSFLOW_NO_REEXEC", "1", 1);
  char self[PATH_MAX] = {};
  const ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
  if (n > 0) execv(self, argv);  // returns only on failure (e.g. the file was replaced): then try /proc/self/exe
  execv("/proc/self/exe", argv);  // returns only on failure: then run with the default policy
}

// More threads than any machine capsflow runs on; beyond it a typo (--threads 1000000) would
// try to start that many.
constexpr int kMaxThreads = 4096;

int main(int argc, char** argv) {
  prefer_passive_openmp_wait(argv);
  spdlog::cfg::load_env_levels();  // SPDLOG_LEVEL=debug|trace: e.g. every step attempt (docs/scene-and-output.md §1.5)
  // A file-size limit (ulimit -f) would kill the run with SIGXFSZ mid-write; ignored, the write
  // fails with EFBIG and takes the full-disk path: exit 1, the last good checkpoint kept.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App cli{"capsflow — an elastic capsule (MITC3 GSMB shell) freely suspended in Stokes flow"};
  cli.require_subcommand(0, 1);
  bool show_version = false;
  cli.add_flag("--version", show_version, "print version, git hash and dependency versions");

  capsflow::app::InfoOptions info;
  CLI::App* info_cmd = cli.add_subcommand("info", "print the resolved scene, mesh report, back end and stable time step");
  info_cmd->add_option("scene", info.scene_path, "scene file (TOML); default: the built-in default scene");
  // One value per --set (repeat the option): CLI11's vector options otherwise also take the scene
  // file that follows them (`run --set a=b SCENE` ran the default scene with SCENE as an override).
  info_cmd->add_option("--set", info.overrides, "override a scene key, e.g. --set mesh.level=5 (repeatable)")
      ->allow_extra_args(false);
  info_cmd->add_flag("--keys", info.keys, "print every scene key: type, default, accepted values, meaning (markdown)");
  info_cmd->add_flag("--probe", info.probe,
                     "evaluate the right-hand side (timing, spectral radius) also above 20 480 elements");

  capsflow::app::RunCommandOptions run;
  CLI::App* run_cmd = cli.add_subcommand("run", "run a scene (default: the built-in quick scene)");
  run_cmd->add_option("scene", run.scene_path, "scene file (TOML); default: the built-in default scene");
  run_cmd->add_option("--set", run.overrides, "override a scene key, e.g. --set time.t_end=1 (repeatable)")
      ->allow_extra_args(false);
  auto* out_opt = run_cmd->add_option("-o,--output", run.output_dir, "output folder (default: capsflow-out)");
  run_cmd->add_flag("--overwrite", run.overwrite, "replace capsflow's files in an existing output folder");
  run_cmd->add_option("--restart", run.restart, "continue from a checkpoint (DIR/checkpoint.h5, or DIR)");
  run_cmd->add_option("--threads", run.threads, "OpenMP threads (default 0: all cores)")->check(CLI::Range(0, kMaxThreads));

  capsflow::app::StudyCommandOptions study;
  CLI::App* study_cmd = cli.add_subcommand("study", "mesh-convergence study: one run per level and vary value, then orders, "
                                                    "Richardson extrapolation and cost (study.md, study.csv, study.json)");
  study_cmd->add_option("scene", study.scene_path, "scene file (TOML); default: the built-in default scene");
  study_cmd->add_option("--levels", study.levels, "consecutive mesh levels, e.g. 3,4,5 (default 3,4,5)");
  // One value per occurrence (repeat the option): CLI11's vector options otherwise also take the
  // scene file that follows them.
  study_cmd->add_option("--vary", study.vary, "one more axis of variants, e.g. --vary fluid.geometry=flat,curved (repeatable)")
      ->allow_extra_args(false);
  study_cmd->add_option("--set", study.overrides, "override a scene key in every variant, e.g. --set time.scheme=rkc (repeatable)")
      ->allow_extra_args(false);
  study_cmd->add_option("-o,--output", study.output_dir, "study folder (default: capsflow-study)");
  study_cmd->add_flag("--overwrite", study.overwrite, "run every variant anew and replace the study files");
  study_cmd->add_flag("--verbose", study.verbose, "show each run's own log (status lines, timing table)");
  study_cmd->add_option("--threads", study.threads, "OpenMP threads (default 0: all cores; with --jobs K: divided among them; "
                                                   "with Slurm: sized per variant)")->check(CLI::Range(0, kMaxThreads));
  study_cmd->add_option("--scheduler", study.scheduler, "where the variants run: local (this machine, the default) or slurm "
                                                        "(one job per variant and an analysis job, through sbatch)");
  study_cmd->add_option("--jobs", study.jobs, "local: variants at once (default 1), threads divided among them")
      ->check(CLI::Range(1, kMaxThreads));
  study_cmd->add_option("--slurm-opt", study.slurm_options, "an sbatch option for every job, e.g. --slurm-opt=--partition=short "
                                                            "(repeatable)")->allow_extra_args(false);
  study_cmd->add_option("--variant", study.variant, "run only this variant of the study (what the jobs run)");
  CLI::Option* analyse_opt = study_cmd->add_option("--analyse", study.analyse, "analyse the study in FOLDER on whatever has "
                                                   "finished, say what is missing (the study as FOLDER/study.json records it)");
  // The analysed study is the one its folder records: an option that would define or run another
  // one is a mistake, not something to ignore.
  for (CLI::Option* o : study_cmd->get_options())
    if (o != analyse_opt && o->get_name() != "--help" && o->get_name() != "--verbose") analyse_opt->excludes(o);

  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);  // prints the help, or the error and a hint
    return code == 0 ? 0 : 2;      // command-line errors: exit code 2 (docs/scene-and-output.md §1.4)
  }
  try {
    if (show_version) {
      const auto b = capsflow::build_info();
      fmt::print("capsflow {} (git {})\n{}\n", b["version"].get<std::string>(), b["git"].get<std::string>(), b.dump(2));
      return 0;
    }
    if (*info_cmd) return capsflow::app::info_command(info);
    if (*run_cmd) {
      run.output_dir_given = out_opt->count() > 0;
      for (int i = 0; i < argc; ++i) run.command_line += (i ? " " : "") + std::string(argv[i]);
      return capsflow::app::run_command(run);
    }
    if (*study_cmd) {
      for (int i = 0; i < argc; ++i) study.command_line += (i ? " " : "") + std::string(argv[i]);
      return capsflow::app::study_command(study);
    }
    fmt::print("{}", cli.help());
    return 0;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "capsflow: error: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "capsflow: error: {}\n", e.what());
    return 1;
  }
}
