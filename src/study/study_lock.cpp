#include "capsflow/core/study/study_lock.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <fmt/core.h>
#include <thread>

namespace capsflow::study {
namespace fs = std::filesystem;

io::FolderLock lock_study_folder(const fs::path& dir, const std::string& holder, double max_wait_seconds) {
  const auto start = std::chrono::steady_clock::now();
  bool said = false;
  for (;;) {
    try {
      io::FolderLock lock = io::FolderLock::acquire(dir, holder);
      if (lock.taken_over())
        spdlog::warn("study folder {}: {}", dir.string(), lock.taken_over()->takeover_note());
      return lock;
    } catch (const io::FolderBusy& busy) {
      const auto h = io::read_lock_holder(dir / io::kFolderLockFile);
      const bool brief = h && (h->command == kSubmissionHolder || h->command == kAnalysisHolder);
      const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (!brief) throw;
      if (waited >= max_wait_seconds)
        throw io::FolderBusy(fmt::format("{} (waited {:.0f} s for it)", busy.what(), waited));
      if (!said)
        spdlog::info("study folder {} is in use by {}, which takes seconds: waiting for it (at most {:.0f} s)", dir.string(),
                     h->describe(), max_wait_seconds);
      said = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

}  // namespace capsflow::study
