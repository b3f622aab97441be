#pragma once
// The manifest of an output folder: exactly the names capsflow writes there, and nothing else
// (docs/scene-and-output.md §3). `--overwrite` removes these and only these; a file named `log`,
// `capsflow.log` or `checkpoint_backup_from_cluster.h5` is the user's and is kept.
// tests/app/test_cli.cpp (Cli.EveryFileWrittenIsInTheManifest) runs capsflow and checks that it
// leaves no other name behind, so the list cannot fall behind the writers.
#include <string>
#include <vector>

namespace capsflow::io {

// run.h5, run.xmf, timeseries.csv, summary.json, checkpoint.h5, checkpoint.prev.h5, and a
// channel's channel.h5 and channel.xmf.
const std::vector<std::string>& output_manifest();

// A leftover of a write that was killed: `<manifest name>.tmp.<pid>` (atomic_file.hpp) or the
// writability probe `.capsflow-write-probe.<pid>` (output_folder.hpp). Sets *pid when given.
bool is_capsflow_temporary_name(const std::string& file_name, long* pid = nullptr);

// A manifest name or one of its leftovers.
bool is_capsflow_output_name(const std::string& file_name);

// A name a running run owns in its folder: a manifest name, one of its leftovers, or the folder's
// lock file (io/folder_lock.hpp). Nothing else may be written there under these names.
bool is_run_folder_name(const std::string& file_name);

}  // namespace capsflow::io
