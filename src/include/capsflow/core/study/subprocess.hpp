#pragma once
// Child processes of a study: the Slurm commands (sbatch, squeue, scontrol) run to completion with
// their output captured, and the --jobs children started and waited for. argv is passed as is
// (no shell), so arguments need no quoting.
#include <sys/types.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace capsflow::study {

// The program's full path when `name` is found on PATH (or is a path to an executable file).
std::optional<std::filesystem::path> find_program(const std::string& name);

struct ProcessOutput {
  int exit_code = -1;  // 128 + signal when killed by one
  std::string out, err;
};
// Runs argv[0] (looked up on PATH) with `input` on its standard input and waits for it. Throws
// std::runtime_error when it cannot be started.
ProcessOutput run_process(const std::vector<std::string>& argv, const std::string& input = "");

// Starts argv[0] with this process's standard output and error; returns its pid. Throws when it
// cannot be started.
pid_t start_process(const std::vector<std::string>& argv);

// This executable's own path (for children that run capsflow again).
std::filesystem::path own_executable();

}  // namespace capsflow::study
