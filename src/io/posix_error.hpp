#pragma once
// Private helper of src/io: one-line errors "what 'path': strerror(errno)".
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace capsflow::io::detail {

[[noreturn]] inline void throw_errno(const std::string& what, const std::filesystem::path& path,
                                     int err = errno) {
  throw std::runtime_error(what + " '" + path.string() + "': " + std::strerror(err));
}

}  // namespace capsflow::io::detail
