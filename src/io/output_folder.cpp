// Output folder preparation (see output_folder.hpp).
#include "capsflow/core/io/output_folder.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>

#include "capsflow/core/io/folder_lock.hpp"
#include "capsflow/core/io/io_error.hpp"

namespace capsflow::io {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& msg) { throw IoError(msg); }

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

// True unless `pid` is certainly not running (kill(pid, 0) fails with ESRCH): the temporary of
// a live capsflow (another run wrongly sharing the folder) is not ours to remove.
bool process_may_be_alive(long pid) {
  if (pid <= 0) return true;
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH;
}

}  // namespace

std::vector<fs::path> remove_stale_temporaries(const fs::path& dir) {
  std::vector<fs::path> stale, removed;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    long pid = 0;
    if (!is_capsflow_temporary_name(it->path().filename().string(), &pid) || process_may_be_alive(pid)) continue;
    if (!it->is_directory(ec) && !it->is_symlink(ec)) stale.push_back(it->path());
  }
  for (const fs::path& p : stale) {
    std::error_code rm;
    if (fs::remove(p, rm)) removed.push_back(p);
  }
  std::sort(removed.begin(), removed.end());
  return removed;
}

void check_writable(const fs::path& dir) {
  const fs::path probe = dir / (".capsflow-write-probe." + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    fail("output folder " + quoted(dir) + " is not writable: " + std::strerror(errno));
  }
  ::close(fd);
  if (::unlink(probe.c_str()) != 0) {
    fail("output folder " + quoted(dir) +
         " is not writable: cannot remove a probe file: " + std::strerror(errno));
  }
}

PreparedFolder prepare_output_folder(const fs::path& dir, bool overwrite) {
  if (dir.empty()) fail("the output folder path is empty");
  PreparedFolder out{dir, {}, {}};
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (fs::exists(st)) {
    if (!fs::is_directory(st)) fail("output path " + quoted(dir) + " exists and is not a folder");
    std::vector<fs::directory_entry> entries;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      if (it->path().filename() != kFolderLockFile) entries.push_back(*it);  // the lock of this very run
    }
    if (ec) fail("cannot list output folder " + quoted(dir) + ": " + ec.message());
    if (!entries.empty() && !overwrite) {
      fail("output folder " + quoted(dir) +
           " exists and is not empty; pass --overwrite to replace it");
    }
    // Probe first: with a read-only folder we must fail before deleting anything.
    check_writable(dir);
    for (const fs::directory_entry& e : entries) {
      const bool ours = is_capsflow_output_name(e.path().filename().string()) &&
                        !e.is_directory(ec) && !e.is_symlink(ec);
      if (!ours) {
        out.kept.push_back(e.path());
        continue;
      }
      if (!fs::remove(e.path(), ec) || ec) {
        fail("cannot remove " + quoted(e.path()) + " from output folder: " + ec.message());
      }
      out.removed.push_back(e.path());
    }
    std::sort(out.removed.begin(), out.removed.end());
    std::sort(out.kept.begin(), out.kept.end());
    return out;
  }
  fs::create_directories(dir, ec);
  if (ec) fail("cannot create output folder " + quoted(dir) + ": " + ec.message());
  check_writable(dir);
  return out;
}

PreparedFolder open_output_folder_for_restart(const fs::path& dir) {
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (!fs::exists(st))
    fail("cannot restart in output folder " + quoted(dir) + ": it does not exist");
  if (!fs::is_directory(st)) fail("output path " + quoted(dir) + " exists and is not a folder");
  check_writable(dir);
  return PreparedFolder{dir, remove_stale_temporaries(dir), {}};
}

}  // namespace capsflow::io
