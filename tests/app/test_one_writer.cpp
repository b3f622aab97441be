// One writer per folder: two real capsflow processes on one folder. The first holds the
// folder's lock for its whole life; the second is refused at once with one line naming the first
// (pid, command), exit 1, and changes nothing. Each test is bounded in time: the first process is
// stopped with SIGTERM (checkpoint and summary, exit 130) as soon as the second has been refused.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <thread>

#include "run_capsflow.hpp"

namespace fs = std::filesystem;

namespace {

using capsflow_test::capsflow;
using capsflow_test::slurp;

struct TempDir : capsflow_test::TempDir {
  TempDir() : capsflow_test::TempDir("one-writer") {}
};

// `capsflow ARGS` in the background (output in LOG); stopped with SIGTERM and reaped at the end.
class Background {
 public:
  Background(const std::string& args, const fs::path& log) {
    pid_ = ::fork();
    if (pid_ == 0) {
      const std::string cmd = "exec " + std::string(CAPSFLOW_EXE) + " " + args + " > " + log.string() + " 2>&1";
      ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
  }
  ~Background() { stop(); }
  pid_t pid() const { return pid_; }
  void forget() { pid_ = -1; }  // reaped by the test itself
  int stop(int signal = SIGTERM) {
    if (pid_ <= 0) return status_;
    ::kill(pid_, signal);
    int st = 0;
    ::waitpid(pid_, &st, 0);
    pid_ = -1;
    return status_ = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  }

 private:
  pid_t pid_ = -1;
  int status_ = -1;
};

// Waits (at most 60 s) until `lock` names a holder: the first process is then past its start-up.
bool wait_for_lock(const fs::path& lock) {
  for (int i = 0; i < 600; ++i) {
    if (fs::exists(lock) && slurp(lock).find("\"pid\"") != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

// Waits (at most 60 s) until `file` exists.
bool wait_for_file(const fs::path& file) {
  for (int i = 0; i < 600 && !fs::exists(file); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  return fs::exists(file);
}

// A run that takes minutes (a membrane capsule at level 2 to γ̇t = 50 on one thread), and one of a
// few seconds.
const std::string kLongRun = "run --set wall.model=membrane --set mesh.level=2 --set time.t_end=50 --threads 1";
const std::string kShortRun = "run --set wall.model=membrane --set mesh.level=1 --set time.t_end=0.05 --threads 1";

// A study that takes minutes: the second one must not wait for it.
const std::string kLongStudy =
    "study --levels 2,3 --set wall.model=membrane --set flow.ca_s=0.2 --set time.t_end=50 --threads 1";

TEST(OneWriter, ASecondStudyOnTheSameFolderIsRefusedNamingTheFirst) {
  TempDir d;
  const fs::path study = d.path / "study";
  Background first(kLongStudy + " -o " + study.string(), d.path / "first.log");
  ASSERT_TRUE(wait_for_lock(study / ".capsflow.lock")) << slurp(d.path / "first.log");
  const auto second = capsflow(kLongStudy + " -o " + study.string(), d.path);
  EXPECT_EQ(second.code, 1) << second.out;
  EXPECT_NE(second.out.find("is in use by pid " + std::to_string(first.pid())), std::string::npos) << second.out;
  EXPECT_NE(second.out.find("capsflow study"), std::string::npos) << second.out;
  // --overwrite does not get past the lock either.
  EXPECT_EQ(capsflow(kLongStudy + " --overwrite -o " + study.string(), d.path).code, 1);
  first.stop();
  EXPECT_FALSE(fs::exists(study / ".capsflow.lock")) << "the first study released its lock when it stopped";
}

TEST(OneWriter, ASecondRunOnTheSameFolderIsRefusedWithOrWithoutOverwriteAndChangesNothing) {
  TempDir d;
  const fs::path run = d.path / "run";
  Background first(kLongRun + " -o " + run.string(), d.path / "first.log");
  ASSERT_TRUE(wait_for_lock(run / ".capsflow.lock")) << slurp(d.path / "first.log");
  for (const std::string extra : {"", " --overwrite"}) {
    const auto second = capsflow(kShortRun + extra + " -o " + run.string(), d.path);
    EXPECT_EQ(second.code, 1) << extra << ": " << second.out;
    EXPECT_NE(second.out.find("is in use by pid " + std::to_string(first.pid())), std::string::npos) << second.out;
    EXPECT_NE(second.out.find("capsflow run"), std::string::npos) << second.out;
  }
  EXPECT_EQ(first.stop(), 130) << slurp(d.path / "first.log");  // SIGTERM: checkpoint, summary, exit 130
  // The first run's files are its own: its summary names the mesh it ran (level 2: 320 elements, the
  // refused level-1 runs have 80) and the run.h5 identity it wrote.
  const auto summary = capsflow_test::json_of(run / "summary.json");
  EXPECT_EQ(summary.at("stop_reason"), "interrupted");
  EXPECT_EQ(summary.at("elements"), 320) << summary.dump();
  EXPECT_FALSE(fs::exists(run / ".capsflow.lock")) << "the first run released its lock when it stopped";
  // Now the folder is free: a restart continues it.
  const auto again = capsflow("run --restart " + run.string() + " --set time.t_end=" +
                                  std::to_string(summary.at("t").get<double>() + 0.02),
                              d.path);
  EXPECT_EQ(again.code, 0) << again.out;
}

TEST(OneWriter, TwoRestartsOfOneFolderAreNotBothAccepted) {
  TempDir d;
  const fs::path run = d.path / "run";
  ASSERT_EQ(capsflow(kShortRun + " -o " + run.string(), d.path).code, 0);
  Background first("run --restart " + run.string() + " --set time.t_end=50", d.path / "first.log");
  ASSERT_TRUE(wait_for_lock(run / ".capsflow.lock")) << slurp(d.path / "first.log");
  const auto second = capsflow("run --restart " + run.string() + " --set time.t_end=0.1", d.path);
  EXPECT_EQ(second.code, 1) << second.out;
  EXPECT_NE(second.out.find("is in use by pid " + std::to_string(first.pid())), std::string::npos) << second.out;
  EXPECT_EQ(first.stop(), 130) << slurp(d.path / "first.log");
}

TEST(OneWriter, TheLockOfAKilledRunIsTakenOverAndItsFirstCheckpointContinues) {
  TempDir d;
  const fs::path run = d.path / "run";
  // No periodic checkpoint (checkpoint_every = 0): the run can reach t = 0.5 before the kill below
  // lands, and a periodic checkpoint there made the restart to t_end = 0.02 refuse (seen once in CI).
  Background first(kLongRun + " --set output.checkpoint_every=0 -o " + run.string(), d.path / "first.log");
  ASSERT_TRUE(wait_for_lock(run / ".capsflow.lock")) << slurp(d.path / "first.log");
  // The checkpoint written as the run starts, the only one until the run ends.
  ASSERT_TRUE(wait_for_file(run / "checkpoint.h5")) << slurp(d.path / "first.log");
  const pid_t killed = first.pid();
  first.stop(SIGKILL);  // no chance to release: the lock file still names it
  ASSERT_TRUE(fs::exists(run / ".capsflow.lock"));
  const auto again = capsflow("run --restart " + run.string() + " --set time.t_end=0.02", d.path);
  EXPECT_EQ(again.code, 0) << again.out;
  EXPECT_NE(again.out.find("took over the lock file of pid " + std::to_string(killed)), std::string::npos) << again.out;
  EXPECT_FALSE(fs::exists(run / ".capsflow.lock"));
}

}  // namespace

namespace {

TEST(OneWriter, ARemovedLockFileLetsNoSecondWriterInAndStopsTheRunThatHeldIt) {
  TempDir d;
  const fs::path run = d.path / "run";
  // Outputs and checkpoints only at t_end (γ̇t = 50): the run writes nothing more until SIGTERM
  // makes it finish, so the second writer below meets it still running.
  Background first(kLongRun + " --set output.every=50 --set output.checkpoint_every=50 -o " + run.string(),
                   d.path / "first.log");
  ASSERT_TRUE(wait_for_lock(run / ".capsflow.lock")) << slurp(d.path / "first.log");
  ASSERT_TRUE(wait_for_file(run / "checkpoint.h5")) << slurp(d.path / "first.log");  // set-up done
  const auto files = [&] {  // each file's name and a hash of its bytes (readable when they differ)
    std::map<std::string, std::size_t> f;
    for (const auto& e : fs::directory_iterator(run)) f[e.path().filename().string()] = std::hash<std::string>{}(slurp(e.path()));
    return f;
  };
  fs::remove(run / ".capsflow.lock");
  const auto before = files();
  const auto second = capsflow(kShortRun + " --overwrite -o " + run.string(), d.path);
  EXPECT_EQ(second.code, 1) << second.out;
  EXPECT_NE(second.out.find("is in use by another capsflow process, whose lock file .capsflow.lock was removed while it ran"),
            std::string::npos)
      << second.out;
  EXPECT_EQ(files(), before) << "the refused writer changed the folder";
  // The holder notices at its next write (here the last ones, at the end): exit 1, one line,
  // nothing more written — no summary.json, the checkpoint as it was.
  EXPECT_EQ(first.stop(), 1) << slurp(d.path / "first.log");
  const std::string log = slurp(d.path / "first.log");
  EXPECT_NE(log.find("capsflow: error: output folder '" + run.string() +
                     "': the lock file .capsflow.lock this process holds was removed while it ran"),
            std::string::npos)
      << log;
  EXPECT_EQ(files(), before);
  // Its checkpoint continues the run.
  const auto again = capsflow("run --restart " + run.string() + " --set time.t_end=0.05", d.path);
  EXPECT_EQ(again.code, 0) << again.out;

  // A run with outputs every few steps notices at the next one, and stops.
  const fs::path busy = d.path / "busy";
  Background writing(kLongRun + " --set output.every=0.01 -o " + busy.string(), d.path / "writing.log");
  ASSERT_TRUE(wait_for_file(busy / "checkpoint.h5")) << slurp(d.path / "writing.log");
  fs::remove(busy / ".capsflow.lock");
  const pid_t pid = writing.pid();
  int status = 0;
  bool ended = false;
  for (int i = 0; i < 600 && !ended; ++i) {  // 60 s bound a run that never notices (minutes of work left)
    ended = ::waitpid(pid, &status, WNOHANG) == pid;
    if (!ended) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_TRUE(ended) << slurp(d.path / "writing.log");
  writing.forget();
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << slurp(d.path / "writing.log");
  EXPECT_NE(slurp(d.path / "writing.log").find("this process holds was removed while it ran"), std::string::npos)
      << slurp(d.path / "writing.log");
  EXPECT_FALSE(fs::exists(busy / "summary.json"));
}

}  // namespace
