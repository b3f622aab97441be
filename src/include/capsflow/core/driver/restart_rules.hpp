#pragma once
// What `capsflow run --restart CHECKPOINT [--set key=value]... [-o DIR]` may do
// (docs/scene-and-output.md §3.6). Decided before anything is written or truncated.
//
// Where the run continues:
//   - in the checkpoint's folder (no -o), or in -o DIR holding the same run: DIR/run.h5 must carry
//     the checkpoint's run id and mesh (io/run_identity.hpp). Its series are cut to the checkpoint
//     time and continued. For files written before run ids, only the checkpoint's own folder with
//     the same mesh is accepted;
//   - in -o DIR that does not exist or is empty: a new run folder starts from the checkpoint. Its
//     history is referenced, not copied: DIR/run.h5 and timeseries.csv start at the checkpoint
//     time, and /metadata records parent_run_id, parent_checkpoint and t_start;
//   - anything else (a folder of another run, or a non-empty folder without run.h5) is refused
//     with one line, and nothing is changed.
//
// Which --set keys apply: everything except the mesh (mesh.*: it comes from the checkpoint) and
// wall.model (the checkpoint holds that wall's state), which are refused when they differ from the
// checkpoint's scene; time.t_end must lie after the checkpoint time (or, for a caller that asks to
// finish a run killed between its last checkpoint and its summary.json, at it). Switching fluid.verify_every
// on or off is refused in the run's own folder (it adds or removes timeseries.csv columns). A changed output.every or
// output.checkpoint_every restarts its index from the checkpoint time (restart_index).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "capsflow/core/io/checkpoint.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

struct RestartPlan {
  Scene scene;                    // the checkpoint's scene with the overrides, checked
  std::filesystem::path folder;   // where the run continues
  bool new_folder = false;        // a new run folder started from the checkpoint
  std::string run_id;             // the run the folder (and new checkpoints) belong to
  std::string parent_run_id;      // new_folder: the checkpoint's run (may be empty for old files)
};

// Throws std::runtime_error (one line) when the restart is refused; changes nothing on disk.
// `checkpoint_path` is the file read (for its folder), `output_dir` the -o argument ("" if none).
// The folder a checkpoint file is in ("." for a bare file name): where a restart continues by default.
std::filesystem::path checkpoint_folder(const std::filesystem::path& checkpoint_path);

// `finish_at_t_end` (RunOptions::finish_at_t_end) also accepts a checkpoint at time.t_end itself.
RestartPlan plan_restart(const io::CheckpointState& checkpoint, const std::filesystem::path& checkpoint_path,
                         const std::vector<std::string>& overrides, const std::string& output_dir,
                         bool finish_at_t_end = false);

// Throws when `next` (the checkpoint's scene `stored` with --set applied) changes what a restart
// cannot change (see above). `t` is the checkpoint time, `elements` its mesh size (for messages).
// With `finish_at_t_end`, t may be time.t_end (within rounding): the run only finishes.
void check_restart_overrides(const Scene& stored, const Scene& next, double t, long elements, bool finish_at_t_end = false);

// The index of the next periodic event (output, checkpoint) for the continued run: the stored one
// when the interval is unchanged (bit-for-bit continuation), else the first k with k·every > t.
std::int64_t restart_index(std::int64_t stored, double old_every, double new_every, double t);

}  // namespace capsflow
