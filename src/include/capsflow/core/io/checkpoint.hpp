#pragma once
// Full-state checkpoints for `--restart` (docs/scene-and-output.md §3.6, docs/time-integration.md §5.12).
//
// write_checkpoint writes `<path>.tmp.<pid>`, fsyncs it, reads it back and compares checksums
// (a full disk has produced files that closed without error but held zeroed data), renames the
// current `<path>` (if any, and only if it is itself readable) to its previous slot
// (checkpoint.h5 → checkpoint.prev.h5), renames the temporary to `<path>` and fsyncs the folder. Whenever the run is killed, at least one complete, valid checkpoint exists:
// the new one, the previous one, or (between the two renames) the previous one in its slot;
// find_latest_checkpoint picks the right one.
//
// File layout (HDF5, format_version 3):
//   attributes on "/": format = "capsflow-checkpoint", format_version, step, t, dt, version,
//                      run_id (io/run_identity.hpp; absent before run ids), mesh_hash (for
//                      readers), checksum (FNV-1a 64 of the whole state, hex; verified on read)
//   datasets: positions [N,3], reference_positions [N,3], triangles int32 [M,3],
//             wall_state [n] (opaque), history [r,c] (opaque), scene_toml, scene_resolved,
//             extra (strings); integrator_state [r,c] (opaque; optional: absent in files written
//             before it existed, which read as empty, and left out of the checksum when empty);
//             fluid_state [r,c] (opaque; empty at λ = 1)
// Doubles are stored as float64 and read back bit for bit.
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "capsflow/core/types.hpp"
#include "capsflow/core/io/io_error.hpp"

namespace capsflow::io {

// The checkpoint format this build writes and reads; any other is refused (no compatibility code).
// 2: the run's time plan under extra["time_plan"], the stabilised stepper's state under
// extra["stabilized_step"], every run-state entry required. 3: the fluid solve's state (λ ≠ 1: the
// second-kind solve's warm start, D̃[1]'s reuse records) as fluid_state and extra["fluid_state"].
inline constexpr std::int64_t kCheckpointFormatVersion = 3;
inline constexpr const char* kCheckpointFile = "checkpoint.h5";

struct CheckpointState {
  std::int64_t step = 0;  // time steps taken so far
  double t = 0;
  double dt = 0;
  Points positions;            // N×3, current
  Points reference_positions;  // N×3, stress-free
  Triangles triangles;         // M×3, indices into the nodes
  Eigen::VectorXd wall_state;  // opaque to io (e.g. nodal directors); any length, may be empty
  Eigen::MatrixXd history;     // opaque to io (e.g. steady-state window samples); may be empty
  Eigen::MatrixXd integrator_state;  // opaque to io (e.g. RKC's F(y_n)); may be empty
  Eigen::MatrixXd fluid_state;       // opaque to io (the fluid solve's warm starts); may be empty
  std::string scene_toml;      // the input scene, verbatim
  std::string scene_resolved;  // the fully resolved scene, JSON text
  std::string version;         // capsflow version + git hash that wrote it
  std::string extra;           // opaque integrator state (JSON text: next output time, ...)
  std::string run_id;          // the run it belongs to (io/run_identity.hpp); empty in old files
};

// "checkpoint.h5" → "checkpoint.prev.h5" (same folder).
std::filesystem::path previous_checkpoint_path(const std::filesystem::path& path);

// Validates `state` (a checkpoint of a blown-up state would push the last good one out of the
// rotation), then writes it atomically as described above. Throws IoError.
void write_checkpoint(const std::filesystem::path& path, const CheckpointState& state);

// Reads and validates (format and version, checksum, dataset shapes, index ranges, finite
// numbers).
// Throws IoError with one line: "checkpoint '<path>': <problem>".
CheckpointState read_checkpoint(const std::filesystem::path& path);

// Throws IoError "checkpoint '<name>': <problem>" if `state` is inconsistent.
void validate_checkpoint(const CheckpointState& state, const std::string& name);

// `--restart PATH`: reads PATH (a folder means PATH/checkpoint.h5). If that is damaged or missing
// and PATH is a checkpoint.h5 whose previous slot reads, returns the previous one instead, with
// the reason in fallback_reason (the caller says so). Throws with both reasons otherwise.
struct LoadedCheckpoint {
  CheckpointState state;
  std::filesystem::path path;   // the file actually read
  std::string fallback_reason;  // non-empty when the previous slot was used
};
LoadedCheckpoint load_checkpoint_for_restart(const std::filesystem::path& path);

// Tests only: called with the temporary file after it was written and synced, before it is
// verified and renamed (to damage it as a full disk would). An empty function removes the hook.
void set_checkpoint_write_hook_for_tests(std::function<void(const std::filesystem::path& tmp)> hook);

// The newest valid checkpoint in `folder`: checkpoint.h5, else checkpoint.prev.h5 (the write was
// interrupted between its two renames, or the newest file is damaged). Throws if neither reads.
std::filesystem::path find_latest_checkpoint(const std::filesystem::path& folder);

}  // namespace capsflow::io
