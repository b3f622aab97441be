// The study folder's lock between the study's commands (study_lock.hpp): the analysis and a Slurm
// submission, which hold it for seconds, wait for each other; a local study, which holds it for
// hours, is not waited for; the wait is bounded. The other holder is another lock on the same file
// (flock excludes two opens of one file within one process as between processes).
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <future>
#include <sstream>
#include <thread>

#include "capsflow/core/study/study_lock.hpp"

using namespace capsflow;
namespace fs = std::filesystem;

namespace {

struct Folder {
  fs::path path = fs::temp_directory_path() / ("capsflow-study-lock-" + std::to_string(::getpid()));
  Folder() { fs::remove_all(path); }
  ~Folder() { fs::remove_all(path); }
};

// The default logger's lines while it lives.
struct Captured {
  std::ostringstream out;
  std::shared_ptr<spdlog::logger> saved = spdlog::default_logger();
  Captured() { spdlog::set_default_logger(std::make_shared<spdlog::logger>("", std::make_shared<spdlog::sinks::ostream_sink_mt>(out))); }
  ~Captured() { spdlog::set_default_logger(saved); }
};

}  // namespace

TEST(StudyLock, TheAnalysisWaitsForASubmissionAndASubmissionForTheAnalysis) {
  const Folder f;
  const std::pair<const char*, const char*> pairs[] = {{study::kSubmissionHolder, study::kAnalysisHolder},
                                                       {study::kAnalysisHolder, study::kSubmissionHolder},
                                                       {study::kAnalysisHolder, study::kLocalStudyHolder}};
  for (const auto& [first, second] : pairs) {
    Captured log;
    io::FolderLock held = io::FolderLock::acquire(f.path, first);
    // The holder lets go a moment after the second command has started waiting.
    auto release = std::async(std::launch::async, [&held] {
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      held.release();
    });
    io::FolderLock mine = study::lock_study_folder(f.path, second, 60);  // 60 s: the bound is not what is tested here
    release.get();
    EXPECT_TRUE(mine.held()) << first << " then " << second;
    EXPECT_NE(log.out.str().find(std::string("is in use by ")), std::string::npos) << log.out.str();
    EXPECT_NE(log.out.str().find(std::string("(capsflow ") + first + ","), std::string::npos) << log.out.str();
    EXPECT_NE(log.out.str().find("waiting for it (at most 60 s)"), std::string::npos) << log.out.str();
  }
}

TEST(StudyLock, ALocalStudyIsNotWaitedForAndTheWaitIsBounded) {
  const Folder f;
  {
    const io::FolderLock held = io::FolderLock::acquire(f.path, study::kLocalStudyHolder);
    const auto start = std::chrono::steady_clock::now();
    try {
      study::lock_study_folder(f.path, study::kAnalysisHolder, 60);
      ADD_FAILURE() << "took the lock of a running local study";
    } catch (const io::FolderBusy& e) {
      EXPECT_NE(std::string(e.what()).find("(capsflow study, started"), std::string::npos) << e.what();
    }
    // Refused at once, not after the 60 s bound (30 s: any scheduling delay of a loaded machine).
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 30.0);
  }
  const io::FolderLock stuck = io::FolderLock::acquire(f.path, study::kSubmissionHolder);
  try {
    study::lock_study_folder(f.path, study::kAnalysisHolder, 0.5);
    ADD_FAILURE() << "took the lock of a submission that holds it";
  } catch (const io::FolderBusy& e) {
    EXPECT_NE(std::string(e.what()).find("capsflow study --scheduler slurm"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(" s for it)"), std::string::npos) << e.what();  // "(waited N s for it)"
  }
}
