#pragma once
// Preparing the output folder of a run (the `-o DIR`, `--overwrite` and `--restart` contract of
// docs/scene-and-output.md §1.1 and §3.1).
//
// A fresh run refuses a non-empty folder unless overwrite is set. With overwrite, only the files
// capsflow itself writes (io/manifest.hpp: exact names and their leftovers) are removed (never a recursive delete of a user folder: `-o ~` must not
// be a disaster); other files are kept and reported. Writability is probed up front so a bad path
// fails before hours of computing, not at the first output step.
#include <filesystem>
#include <string>
#include <vector>

#include "capsflow/core/io/manifest.hpp"
#include "capsflow/core/io/io_error.hpp"

namespace capsflow::io {

struct PreparedFolder {
  std::filesystem::path path;
  std::vector<std::filesystem::path> removed;  // capsflow files deleted because of overwrite
  std::vector<std::filesystem::path> kept;     // other entries left in place (for a log line)
};


// Create `dir` (with parents) for a new run. Throws IoError (one line) when it is not
// a folder, is non-empty without `overwrite`, cannot be created, or is not writable.
PreparedFolder prepare_output_folder(const std::filesystem::path& dir, bool overwrite);

// Open an existing run folder for continuation (`--restart`): it must exist, be a folder and be
// writable; only stale temporaries are removed (`removed`). Truncating the series is
// ResultsWriter::reopen's job; whether the folder belongs to the checkpoint's run is
// driver/restart_rules.hpp's.
PreparedFolder open_output_folder_for_restart(const std::filesystem::path& dir);

// Removes the leftovers `<manifest name>.tmp.<pid>` of writes killed mid-way whose process is
// gone (a live pid's temporary is kept). Returns what was removed.
std::vector<std::filesystem::path> remove_stale_temporaries(const std::filesystem::path& dir);

// Create and remove a probe file in `dir`; throws "output folder 'X' is not writable: <reason>".
void check_writable(const std::filesystem::path& dir);

}  // namespace capsflow::io
