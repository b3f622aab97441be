#pragma once
// Sub-commands of the capsflow executable (docs/scene-and-output.md §1).
#include <string>
#include <vector>

namespace capsflow::app {

struct InfoOptions {
  std::string scene_path;  // empty: built-in default scene
  std::vector<std::string> overrides;
  // Evaluate the right-hand side (time per evaluation, spectral radius by power iteration):
  // automatic up to kInfoProbeElements elements (info/scene_info.hpp), forced by --probe.
  bool probe = false;
  bool keys = false;  // print the scene keys (the tables of docs/scene-and-output.md §2) instead
};
int info_command(const InfoOptions& opt);

struct RunCommandOptions {
  std::string scene_path;  // empty: built-in default scene
  std::vector<std::string> overrides;
  std::string output_dir = "capsflow-out";
  bool output_dir_given = false;
  bool overwrite = false;
  std::string restart;
  int threads = 0;
  std::string command_line;
};
int run_command(const RunCommandOptions& opt);

struct StudyCommandOptions {
  std::string scene_path;  // empty: built-in default scene
  std::vector<std::string> overrides;
  std::string levels = "3,4,5";
  std::vector<std::string> vary;  // "section.key=v1,v2,..."
  std::string output_dir = "capsflow-study";
  bool overwrite = false;
  bool verbose = false;
  int threads = 0;
  std::string command_line;
  std::string scheduler = "local";
  int jobs = 1;
  std::vector<std::string> slurm_options;
  std::string analyse;  // --analyse DIR
  std::string variant;  // --variant NAME (the jobs' entry point)
};
int study_command(const StudyCommandOptions& opt);

}  // namespace capsflow::app
