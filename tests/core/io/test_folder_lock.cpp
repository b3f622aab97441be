// FolderLock: one writer per folder; a second writer is refused naming the holder; a lock left by a
// process killed with SIGKILL is taken over and reported; release removes the lock file.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include "capsflow/core/io/folder_lock.hpp"
#include "capsflow/core/io/output_folder.hpp"
#include "temp_dir.hpp"

namespace capsflow::io {
namespace {
using testing::read_text;
using testing::TempDir;
using testing::write_text;

TEST(FolderLock, CreatesTheFolderAndNamesItsHolder) {
  TempDir dir;
  const auto out = dir / "a/b";
  FolderLock lock = FolderLock::acquire(out, "run");
  EXPECT_TRUE(lock.held());
  const auto h = read_lock_holder(out / kFolderLockFile);
  ASSERT_TRUE(h.has_value());
  EXPECT_EQ(h->pid, static_cast<long>(::getpid()));
  EXPECT_EQ(h->command, "run");
  EXPECT_FALSE(lock.taken_over().has_value());  // a fresh folder has no earlier holder
}

// flock locks belong to an open file description, so a second acquire in the same process
// conflicts exactly as a second process would.
TEST(FolderLock, ASecondWriterIsRefusedWithTheHoldersPidAndChangesNothing) {
  TempDir dir;
  FolderLock first = FolderLock::acquire(dir.path(), "run");
  const std::string before = read_text(dir / kFolderLockFile);
  try {
    FolderLock second = FolderLock::acquire(dir.path(), "study");
    FAIL() << "the second writer was let in";
  } catch (const FolderBusy& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("is in use by pid " + std::to_string(::getpid())), std::string::npos) << msg;
    EXPECT_NE(msg.find("capsflow run"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line";
  }
  EXPECT_EQ(read_text(dir / kFolderLockFile), before);  // the refused writer did not touch it
  EXPECT_TRUE(first.held());
}

TEST(FolderLock, ReleaseRemovesTheLockFileAndLetsTheNextWriterIn) {
  TempDir dir;
  {
    FolderLock lock = FolderLock::acquire(dir.path(), "run");
  }
  EXPECT_FALSE(std::filesystem::exists(dir / kFolderLockFile));
  FolderLock again = FolderLock::acquire(dir.path(), "run");
  EXPECT_FALSE(again.taken_over().has_value());  // released cleanly: nothing stale to report
}

TEST(FolderLock, ALockFileNobodyHoldsIsTakenOverAndItsHolderReported) {
  TempDir dir;
  write_text(dir / kFolderLockFile,
             R"({"pid": 4194300, "host": "node7", "started_utc": "2026-01-01T00:00:00Z", "command": "run"})");
  FolderLock lock = FolderLock::acquire(dir.path(), "run");
  ASSERT_TRUE(lock.taken_over().has_value());
  EXPECT_EQ(lock.taken_over()->pid, 4194300);
  EXPECT_EQ(lock.taken_over()->host, "node7");
  EXPECT_EQ(read_lock_holder(dir / kFolderLockFile)->pid, static_cast<long>(::getpid()));  // now ours
}

// A real second process holds the lock, then dies by SIGKILL (no destructor runs): the kernel
// drops its flock, the file still names it, and the next writer takes over saying whose it was.
TEST(FolderLock, TheLockOfAProcessKilledWithSigkillIsTakenOver) {
  TempDir dir;
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    try {
      FolderLock lock = FolderLock::acquire(dir.path(), "run");
      char c = 'x';
      if (::write(ready[1], &c, 1) != 1) ::_exit(2);
      for (;;) ::pause();
    } catch (...) {
      ::_exit(3);
    }
  }
  ::close(ready[1]);
  char c = 0;
  ASSERT_EQ(::read(ready[0], &c, 1), 1) << "the child did not take the lock";
  ::close(ready[0]);
  EXPECT_THROW(FolderLock::acquire(dir.path(), "run"), FolderBusy);  // held by the live child
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  FolderLock lock = FolderLock::acquire(dir.path(), "run");
  ASSERT_TRUE(lock.taken_over().has_value());
  EXPECT_EQ(lock.taken_over()->pid, static_cast<long>(child));
}

TEST(FolderLock, TheLockFileDoesNotMakeAFolderNonEmpty) {
  TempDir dir;
  FolderLock lock = FolderLock::acquire(dir.path(), "run");
  EXPECT_NO_THROW(prepare_output_folder(dir.path(), false));
  write_text(dir / "run.h5", "previous results");
  const PreparedFolder p = prepare_output_folder(dir.path(), true);
  EXPECT_TRUE(std::filesystem::exists(dir / kFolderLockFile)) << "--overwrite must not remove the lock";
  EXPECT_TRUE(p.kept.empty());  // the lock is not reported as a user file
}

// A lock file removed under its holder (rm, a clean-up script) once let the next writer create a
// fresh one and lock it: two writers in one folder, neither aware of the other.
TEST(FolderLock, ARemovedLockFileLetsNoSecondWriterInAndItsHolderNoticesIt) {
  namespace fs = std::filesystem;
  TempDir dir;
  FolderLock first = FolderLock::acquire(dir.path(), "run");
  EXPECT_NO_THROW(first.check_held());
  fs::remove(dir / kFolderLockFile);
  try {
    FolderLock second = FolderLock::acquire(dir.path(), "run");
    FAIL() << "the second writer was let in";
  } catch (const FolderBusy& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("is in use by another capsflow process, whose lock file .capsflow.lock was removed while it ran"),
              std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line";
  }
  EXPECT_FALSE(fs::exists(dir / kFolderLockFile)) << "the refused writer left a lock file";
  try {
    first.check_held();
    FAIL() << "the holder did not notice";
  } catch (const FolderLockLost& e) {
    EXPECT_NE(std::string(e.what()).find(".capsflow.lock this process holds was removed while it ran"), std::string::npos)
        << e.what();
  }
  // Replaced by another file of that name: noticed too (another inode), and left alone on release.
  write_text(dir / kFolderLockFile, "not yours");
  EXPECT_THROW(first.check_held(), FolderLockLost);
  first.release();
  EXPECT_EQ(read_text(dir / kFolderLockFile), "not yours");
  EXPECT_NO_THROW(FolderLock::acquire(dir.path(), "run"));  // released: the folder is free again
}

TEST(FolderLock, RefusesAPathThatIsAFile) {
  TempDir dir;
  write_text(dir / "f", "x");
  EXPECT_THROW(FolderLock::acquire(dir / "f", "run"), std::runtime_error);
}

}  // namespace
}  // namespace capsflow::io
