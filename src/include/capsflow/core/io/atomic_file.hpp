#pragma once
// Whole-file atomic replacement: readers (ParaView, scripts, a restart) see either the old file or
// the complete new one, never a truncated one, even if the run is killed mid-write.
//
// Recipe: write `<name>.tmp.<pid>` in the target's folder (same file system, so rename() is
// atomic), fsync it, rename() it over the target, fsync the folder so the rename itself survives
// a power loss. Errors throw IoError with one line naming the path and strerror(errno).
#include <filesystem>
#include <functional>
#include <string_view>

#include "capsflow/core/io/io_error.hpp"

namespace capsflow::io {

// The temporary sibling used for `target`: same folder, name `<target name>.tmp.<pid>`.
std::filesystem::path temporary_sibling(const std::filesystem::path& target);

// Replace `target` with `content` atomically.
void write_file_atomically(const std::filesystem::path& target, std::string_view content);

// For writers that need a path rather than bytes (HDF5): `write(tmp)` must create and close the
// file at `tmp`; it is then fsynced and renamed over `target`. If `write` throws, the temporary
// is removed and `target` is untouched.
void replace_file_atomically(const std::filesystem::path& target,
                             const std::function<void(const std::filesystem::path& tmp)>& write);

// fsync an existing file (or folder) by path. Throws on failure.
void fsync_path(const std::filesystem::path& path);

// rename(from, to) followed by fsync of the folder of `to`. Throws on failure.
void rename_durably(const std::filesystem::path& from, const std::filesystem::path& to);

}  // namespace capsflow::io
