#pragma once
// The identity of a run folder (docs/scene-and-output.md §3.7): a run id, drawn once when a run
// starts in a folder, and the hash of its reference mesh. Both are stored in run.h5:/metadata
// (`run_id`, `mesh_hash`), in every checkpoint (attributes `run_id`, `mesh_hash`) and in
// summary.json, so that `--restart` can tell whether a checkpoint belongs to a folder before it
// truncates anything there (driver/restart_rules.hpp).
#include <filesystem>
#include <string>

#include "capsflow/core/types.hpp"
#include "capsflow/core/io/io_error.hpp"

namespace capsflow::io {

// 32 hex digits from std::random_device (128 bits: two runs never share one).
std::string new_run_id();

// FNV-1a 64 (hex) of the reference positions and triangles, shapes included, bit for bit.
std::string mesh_hash(const Points& reference_positions, const Triangles& triangles);

struct FolderIdentity {
  bool has_run = false;   // DIR/run.h5 exists
  std::string run_id;     // /metadata/run_id, else the newest /metadata/restarts/<n>/run_id; empty for
                          // a run.h5 written before run ids
  std::string mesh_hash;  // of /mesh/reference_positions and /mesh/triangles
};

// Reads DIR/run.h5. Throws IoError (one line) when run.h5 exists but cannot be read.
FolderIdentity read_folder_identity(const std::filesystem::path& dir);

}  // namespace capsflow::io
