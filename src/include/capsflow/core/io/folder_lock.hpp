#pragma once
// One writer per output folder: an exclusive lock on `<dir>/.capsflow.lock`, taken before any
// overwrite, identity or restart decision and held for the life of the run (or study).
//
// The lock is flock(2) on the lock file, so the kernel releases it when the holder dies, however it
// dies; the file's content only names the holder (pid, host, start time, command) for the message a
// refused writer prints. The folder itself is flocked as well, so a lock file removed while its
// holder runs does not let a second writer in; and the holder checks before each write that its
// lock file is still the folder's (check_held), stopping with FolderLockLost when it is not. A lock file that we can lock but that still names a holder was left by a
// process that died without releasing it (kill -9, power loss): it is taken over and reported.
// A holder that ends normally removes the file. Readers (ParaView, `capsflow info`, Python's
// read_run) never take the lock and are never blocked.
//
// On NFS, Linux emulates flock with whole-file POSIX locks held by the server, so two hosts exclude
// each other as long as the mount has working locking (not `nolock` / `local_lock=all`, under which
// each client only sees its own locks); a client that dies loses its lock when the server's lease
// expires (NFSv4: ~90 s). docs/scene-and-output.md §1.1.
#include <filesystem>
#include <optional>
#include <string>

#include "capsflow/core/io/io_error.hpp"

namespace capsflow::io {

inline constexpr const char* kFolderLockFile = ".capsflow.lock";

// What a lock file says about its holder.
struct LockHolder {
  long pid = 0;
  std::string host;
  std::string started_utc;  // ISO 8601
  std::string command;      // "run", "study", ...
  std::string describe() const;  // "pid 123 on host h (capsflow run, started 2026-12-01T18:20:31Z)"
  // What the taker of a lock file this holder left unheld says: the holder ended without releasing
  // it, or the folder is a copy made while it ran (its pid may be alive, holding the original).
  std::string takeover_note() const;
};

// Another process holds the lock: what() is the one-line message naming the holder.
class FolderBusy : public IoError {
 public:
  using IoError::IoError;
};

// The lock file a holder locked is no longer the one in its folder (removed or replaced): the
// holder cannot tell whether another writer is there now. what() is the one-line message.
class FolderLockLost : public IoError {
 public:
  using IoError::IoError;
};

class FolderLock {
 public:
  // Creates `dir` (with parents) when missing and takes its lock. Throws FolderBusy when another
  // process holds it, IoError when the lock file cannot be created. `command` names the
  // holder's job in the message another writer gets ("run", "study").
  static FolderLock acquire(const std::filesystem::path& dir, const std::string& command);

  FolderLock() = default;
  FolderLock(FolderLock&& o) noexcept;
  FolderLock& operator=(FolderLock&& o) noexcept;
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  ~FolderLock();  // release(): removes the lock file, then unlocks

  void release();
  bool held() const { return fd_ >= 0; }
  // Throws FolderLockLost when the lock file this lock holds is no longer the file at path()
  // (same device and inode): someone removed or replaced it. Nothing when not held. Called before
  // each write into the folder (driver: every output, checkpoint and finish).
  void check_held() const;
  const std::filesystem::path& path() const { return path_; }
  // The holder named by a lock file left behind by a process that died holding it (taken over).
  const std::optional<LockHolder>& taken_over() const { return stale_; }

 private:
  int fd_ = -1;
  int dir_fd_ = -1;  // the folder itself, flocked too (-1 where folders cannot be flocked)
  std::filesystem::path path_;
  std::optional<LockHolder> stale_;
};

// True when `dir` holds nothing but (possibly) its lock file: a folder locked by this very run is
// still an empty folder for the decisions taken under the lock.
bool is_empty_but_for_lock(const std::filesystem::path& dir);

// The holder a lock file names, if it names one (empty or unreadable: nullopt). For messages only.
std::optional<LockHolder> read_lock_holder(const std::filesystem::path& lock_file);

// Whether another open lock (another process, or another FolderLock of this one) holds `dir`; its
// holder as the lock file names it (pid 0 when it names none). Probes with a shared lock taken and
// dropped at once; never creates the lock file. For refusing to write into another run's folder.
std::optional<LockHolder> folder_held_by_another(const std::filesystem::path& dir);

}  // namespace capsflow::io
