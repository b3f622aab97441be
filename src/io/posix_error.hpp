#pragma once
// Private helper of src/io: one-line errors "what 'path': strerror(errno)".
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

#include "capsflow/core/io/io_error.hpp"

namespace capsflow::io::detail {

[[noreturn]] inline void throw_errno(const std::string& what, const std::filesystem::path& path,
                                     int err = errno) {
  throw IoError(what + " '" + path.string() + "': " + std::strerror(err));
}

}  // namespace capsflow::io::detail
