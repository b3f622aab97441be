// Atomic whole-file replacement (see atomic_file.hpp).
#include "capsflow/core/io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <string>
#include <system_error>

#include "posix_error.hpp"

namespace capsflow::io {
namespace fs = std::filesystem;
using detail::throw_errno;

namespace {

// The folder holding `p`, as a path that open() accepts ("." for a bare file name).
fs::path folder_of(const fs::path& p) {
  fs::path parent = p.parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

void fsync_fd(int fd, const fs::path& path) {
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    throw_errno("cannot fsync", path, err);
  }
}

void remove_quietly(const fs::path& p) {
  std::error_code ec;
  fs::remove(p, ec);  // best effort: we are already reporting a more important error
}

}  // namespace

fs::path temporary_sibling(const fs::path& target) {
  fs::path tmp = target;
  tmp += ".tmp." + std::to_string(::getpid());
  return tmp;
}

void fsync_path(const fs::path& path) {
  // O_RDONLY works for folders too; fsync on a read-only descriptor is allowed on Linux.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw_errno("cannot open for fsync", path);
  fsync_fd(fd, path);
  ::close(fd);
}

void rename_durably(const fs::path& from, const fs::path& to) {
  if (::rename(from.c_str(), to.c_str()) != 0) {
    throw_errno("cannot rename '" + from.string() + "' to", to);
  }
  fsync_path(folder_of(to));
}

void write_file_atomically(const fs::path& target, std::string_view content) {
  const fs::path tmp = temporary_sibling(target);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw_errno("cannot create", tmp);
  const char* p = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      remove_quietly(tmp);
      throw_errno("cannot write", tmp, err);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  try {
    fsync_fd(fd, tmp);
  } catch (...) {
    remove_quietly(tmp);
    throw;
  }
  if (::close(fd) != 0) {  // NFS reports deferred write errors at close
    const int err = errno;
    remove_quietly(tmp);
    throw_errno("cannot close", tmp, err);
  }
  try {
    rename_durably(tmp, target);
  } catch (...) {
    remove_quietly(tmp);
    throw;
  }
}

void replace_file_atomically(const fs::path& target,
                             const std::function<void(const fs::path& tmp)>& write) {
  const fs::path tmp = temporary_sibling(target);
  try {
    write(tmp);
    fsync_path(tmp);
    rename_durably(tmp, target);
  } catch (...) {
    remove_quietly(tmp);
    throw;
  }
}

}  // namespace capsflow::io
