#pragma once
// The files capsflow reads (scenes, meshes) are regular files of bounded size. A FIFO, a device
// (/dev/zero) or a folder given as a scene or mesh would block open() or read for ever; a file
// larger than any scene or mesh capsflow can run is a mistake, not an input. Checked before open.
#include <cstdint>
#include <string>

namespace capsflow::io {

// The largest scene file (a scene is a few kB of TOML) and mesh file (ASCII OFF at 16 M elements
// is ~1 GB; 327 680 elements, the largest mesh in the docs, is ~20 MB).
inline constexpr std::uintmax_t kMaxSceneBytes = std::uintmax_t{64} << 20;
inline constexpr std::uintmax_t kMaxMeshBytes = std::uintmax_t{1} << 30;

// Returns "" when `path` names a regular file (after symbolic links) of at most max_bytes, else
// why not, as a predicate of "it" ("is a FIFO, not a regular file", "does not exist", "cannot be accessed: …").
std::string input_file_problem(const std::string& path, std::uintmax_t max_bytes);

}  // namespace capsflow::io
