#pragma once
// The command line that runs one variant of a study by itself — the study's own command with
// `--variant NAME` — as a --jobs child and in a Slurm job's script. The scene and the study folder
// are absolute paths, so it runs from any working directory.
#include <string>
#include <vector>

#include "capsflow/core/study/study_runner.hpp"

namespace capsflow::study {

// argv: EXE study [SCENE] --levels … [--set …]… [--vary …]… -o DIR --variant NAME [--overwrite] [--threads T].
// `threads` 0 leaves --threads out; `variant` "" leaves --variant out (the script adds it).
std::vector<std::string> variant_command(const std::string& exe, const StudyOptions& o, const std::string& variant,
                                         int threads);

// One shell word: as is when it is made of safe characters, else in single quotes.
std::string shell_quote(const std::string& word);

}  // namespace capsflow::study
