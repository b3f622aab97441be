// Regular files of bounded size only (see input_file.hpp).
#include "capsflow/core/io/input_file.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <fmt/core.h>

namespace capsflow::io {

std::string input_file_problem(const std::string& path, std::uintmax_t max_bytes) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return errno == ENOENT ? "does not exist" : std::string("cannot be accessed: ") + std::strerror(errno);
  const auto type = st.st_mode & S_IFMT;
  if (type == S_IFDIR) return "is a folder, not a file";
  if (type != S_IFREG) {
    const char* what = type == S_IFIFO ? "a FIFO" : type == S_IFCHR ? "a character device" : type == S_IFBLK ? "a block device"
                       : type == S_IFSOCK                        ? "a socket"
                                                                 : "not a regular file";
    return fmt::format("is {}, not a regular file (capsflow reads its input from regular files only)", what);
  }
  const auto size = static_cast<std::uintmax_t>(st.st_size);
  if (size > max_bytes)
    return fmt::format("is {:.1f} MB, larger than the {:.0f} MB capsflow accepts for this kind of file", static_cast<double>(size) / 1048576.0,
                       static_cast<double>(max_bytes) / 1048576.0);
  return "";
}

}  // namespace capsflow::io
