#pragma once
// The files capsflow reads (scenes, meshes, checkpoints, a study's study.json and its variants'
// summary.json, timeseries.csv and job record) are regular files, scenes and meshes of bounded
// size. A FIFO, a device (/dev/zero) or a folder in their place would block open() or read for
// ever; a scene or mesh larger than any capsflow can run is a mistake, not an input. Checked
// before open.
#include <cstdint>
#include <limits>
#include <string>

namespace capsflow::io {

// The largest scene file (a scene is a few kB of TOML) and mesh file (ASCII OFF at 16 M elements
// is ~1 GB; 327 680 elements, the largest mesh in the docs, is ~20 MB).
inline constexpr std::uintmax_t kMaxSceneBytes = std::uintmax_t{64} << 20;
inline constexpr std::uintmax_t kMaxMeshBytes = std::uintmax_t{1} << 30;
// Checkpoints and results: their size follows the mesh and the run, so only their type is checked.
inline constexpr std::uintmax_t kAnyFileSize = std::numeric_limits<std::uintmax_t>::max();

// Returns "" when `path` names a regular file (after symbolic links) of at most max_bytes, else
// why not, as a predicate of "it" ("is a FIFO, not a regular file", "does not exist", "cannot be accessed: …").
std::string input_file_problem(const std::string& path, std::uintmax_t max_bytes);

}  // namespace capsflow::io
