// The exclusive lock of an output folder (see folder_lock.hpp).
#include "capsflow/core/io/folder_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

namespace capsflow::io {
namespace fs = std::filesystem;

namespace {

std::string host_name() {
  char buf[256] = {};
  return ::gethostname(buf, sizeof buf - 1) == 0 ? std::string(buf) : std::string("?");
}

std::string now_utc() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  ::gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::optional<LockHolder> parse_holder(const std::string& text) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("pid")) return std::nullopt;
  LockHolder h;
  h.pid = j.value("pid", 0L);
  h.host = j.value("host", std::string("?"));
  h.started_utc = j.value("started_utc", std::string("?"));
  h.command = j.value("command", std::string("?"));
  return h;
}

std::string read_fd(int fd) {
  std::string text;
  char buf[4096];
  for (off_t at = 0;;) {
    const ssize_t n = ::pread(fd, buf, sizeof buf, at);
    if (n <= 0 || text.size() > 65536) break;  // the holder's line is short; bound a corrupt file
    text.append(buf, static_cast<std::size_t>(n));
    at += n;
  }
  return text;
}

// True when `fd` is still the file at `path`: a holder that released between our open() and
// flock() unlinked the file we opened, and a lock on an unlinked file excludes nobody.
bool still_linked(int fd, const fs::path& path) {
  struct stat a {}, b {};
  return ::fstat(fd, &a) == 0 && ::stat(path.c_str(), &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

}  // namespace

std::string LockHolder::describe() const {
  if (pid == 0) return "another capsflow process";  // a lock file that names no holder
  return fmt::format("pid {} on host {} (capsflow {}, started {})", pid, host, command, started_utc);
}

std::string LockHolder::takeover_note() const {
  return fmt::format("took over the lock file of {}, which no process held (it ended without releasing it, or this "
                     "folder was copied while it ran)",
                     describe());
}

std::optional<LockHolder> read_lock_holder(const fs::path& lock_file) {
  const int fd = ::open(lock_file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return std::nullopt;
  const std::string text = read_fd(fd);
  ::close(fd);
  return parse_holder(text);
}

namespace {
// Whether another open lock holds `fd` (probed with a shared lock, dropped at once).
bool held_elsewhere(int fd) {
  if (::flock(fd, LOCK_SH | LOCK_NB) != 0) return errno == EWOULDBLOCK;
  ::flock(fd, LOCK_UN);
  return false;
}
}  // namespace

std::optional<LockHolder> folder_held_by_another(const fs::path& dir) {
  const fs::path lock_file = dir / kFolderLockFile;
  const int fd = ::open(lock_file.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (fd >= 0) {
    const bool held = held_elsewhere(fd);
    const std::optional<LockHolder> named = held ? parse_holder(read_fd(fd)) : std::nullopt;
    ::close(fd);
    if (held) return named.value_or(LockHolder{});
  }
  // The folder's own lock: held also when its lock file was removed.
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd < 0) return std::nullopt;
  const bool held = held_elsewhere(dir_fd);
  ::close(dir_fd);
  return held ? std::optional<LockHolder>(LockHolder{}) : std::nullopt;
}

bool is_empty_but_for_lock(const fs::path& dir) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().filename() != kFolderLockFile) return false;
  return true;
}

FolderLock FolderLock::acquire(const fs::path& dir, const std::string& command) {
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (fs::exists(st) && !fs::is_directory(st)) throw IoError("output path '" + dir.string() + "' exists and is not a folder");
  fs::create_directories(dir, ec);
  if (ec) throw IoError("cannot create output folder '" + dir.string() + "': " + ec.message());
  FolderLock lock;
  lock.path_ = dir / kFolderLockFile;
  // The folder itself is locked first: a lock file removed while its holder runs (rm, a clean-up
  // script) must not let a second writer in. Where a folder cannot be flocked (NFS emulates flock
  // with POSIX locks, which need a file open for writing) the lock file alone decides.
  lock.dir_fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (lock.dir_fd_ >= 0 && ::flock(lock.dir_fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    ::close(lock.dir_fd_);
    lock.dir_fd_ = -1;
    if (err == EWOULDBLOCK) {
      const std::optional<LockHolder> h = read_lock_holder(lock.path_);
      const bool file = fs::exists(lock.path_, ec);
      throw FolderBusy(fmt::format("output folder '{}' is in use by {}: one writer per folder (wait for it to end, or choose "
                                   "another folder)",
                                   dir.string(),
                                   h      ? h->describe()
                                   : file ? std::string("another capsflow process that is starting")
                                          : fmt::format("another capsflow process, whose lock file {} was removed while it "
                                                        "ran",
                                                        kFolderLockFile)));
    }
  }
  for (int attempt = 0;; ++attempt) {
    const int fd = ::open(lock.path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd < 0)
      throw IoError(fmt::format("cannot create the lock file '{}': {}", lock.path_.string(), std::strerror(errno)));
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      const std::optional<LockHolder> h = parse_holder(read_fd(fd));
      ::close(fd);
      if (err != EWOULDBLOCK)
        throw IoError(fmt::format("cannot lock '{}': {}", lock.path_.string(), std::strerror(err)));
      throw FolderBusy(fmt::format("output folder '{}' is in use by {}: one writer per folder (wait for it to end, or choose "
                                   "another folder)",
                                   dir.string(), h ? h->describe() : "another capsflow process that is starting"));
    }
    if (!still_linked(fd, lock.path_)) {  // released (and removed) between our open and flock: retry
      ::close(fd);
      if (attempt < 100) continue;
      throw IoError("cannot lock '" + lock.path_.string() + "': the lock file keeps being replaced");
    }
    lock.fd_ = fd;
    break;
  }
  lock.stale_ = parse_holder(read_fd(lock.fd_));  // a holder named here died without releasing
  const std::string me = nlohmann::json{{"pid", static_cast<long>(::getpid())}, {"host", host_name()},
                                        {"started_utc", now_utc()}, {"command", command}}
                             .dump() +
                         "\n";
  if (::ftruncate(lock.fd_, 0) != 0 || ::pwrite(lock.fd_, me.data(), me.size(), 0) != static_cast<ssize_t>(me.size()))
    throw IoError(fmt::format("cannot write the lock file '{}': {}", lock.path_.string(), std::strerror(errno)));
  return lock;
}

FolderLock::FolderLock(FolderLock&& o) noexcept
    : fd_(o.fd_), dir_fd_(o.dir_fd_), path_(std::move(o.path_)), stale_(std::move(o.stale_)) {
  o.fd_ = -1;
  o.dir_fd_ = -1;
}

FolderLock& FolderLock::operator=(FolderLock&& o) noexcept {
  if (this != &o) {
    release();
    fd_ = o.fd_;
    dir_fd_ = o.dir_fd_;
    path_ = std::move(o.path_);
    stale_ = std::move(o.stale_);
    o.fd_ = -1;
    o.dir_fd_ = -1;
  }
  return *this;
}

FolderLock::~FolderLock() { release(); }

void FolderLock::release() {
  // The folder first: a writer that gets it meanwhile still meets the lock file's flock, and its
  // message names this holder.
  if (dir_fd_ >= 0) {
    ::close(dir_fd_);
    dir_fd_ = -1;
  }
  if (fd_ >= 0) {
    // Unlink while still holding the lock: a process that opened the file meanwhile finds it
    // unlinked after its flock() succeeds and retries on a fresh file (still_linked above). A file
    // that is no longer ours (ours was removed, another took its name) is left alone.
    if (still_linked(fd_, path_)) ::unlink(path_.c_str());
    ::close(fd_);  // closing the last descriptor releases the flock
    fd_ = -1;
  }
}

void FolderLock::check_held() const {
  if (fd_ < 0 || still_linked(fd_, path_)) return;
  std::error_code ec;
  throw FolderLockLost(fmt::format("output folder '{}': the lock file {} this process holds was {} while it ran, so another "
                                   "writer may be using the folder: stopping without writing more there (the last "
                                   "checkpoint continues the run)",
                                   path_.parent_path().string(), kFolderLockFile,
                                   fs::exists(path_, ec) ? "replaced" : "removed"));
}

}  // namespace capsflow::io
