#pragma once
// The study folder's lock (io/folder_lock.hpp), as each study command takes it: one writer of the
// study files at a time. Its holders, by the name the lock file gives them:
//   "study"                   a local study, for its whole life (hours): anyone else is refused;
//   "study --scheduler slurm" a submission, for seconds (squeue, sbatch);
//   "study --analyse"         the analysis (the Slurm study's analysis job, or by hand), for seconds.
// A command that meets one of the brief holders waits for it, bounded, saying so: the analysis
// job, which nobody watches, must not fail because the user resubmitted at that moment, and a
// resubmission must not fail because the analysis job was writing. The variants (--variant, the
// jobs and --jobs children) never take it: they write only their own run folders.
#include <filesystem>
#include <string>

#include "capsflow/core/io/folder_lock.hpp"

namespace capsflow::study {

inline constexpr const char* kLocalStudyHolder = "study";
inline constexpr const char* kSubmissionHolder = "study --scheduler slurm";
inline constexpr const char* kAnalysisHolder = "study --analyse";
// How long a brief holder is waited for: far beyond the seconds it holds the lock, also with a
// slow slurmctld; a holder still there then is stuck, and the message names it.
inline constexpr double kBriefHolderWaitSeconds = 120;

// Takes DIR's lock as `holder` (one of the names above). Throws io::FolderBusy (one line naming
// the holder) when a local study holds it, or a brief holder still does after max_wait_seconds.
io::FolderLock lock_study_folder(const std::filesystem::path& dir, const std::string& holder,
                                 double max_wait_seconds = kBriefHolderWaitSeconds);

}  // namespace capsflow::study
