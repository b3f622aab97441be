#pragma once
// The Slurm commands a study uses, and the parsing of their answers (docs/study.md §Slurm):
// `sbatch --parsable` (and `--test-only`, which checks a submission without making it),
// `squeue` for the jobs still queued or running, and `scontrol show job` for how a job that left
// the queue ended while slurmctld still remembers it (MinJobAge, 300 s by default). No accounting
// daemon is assumed: `sacct` is not used; what a variant produced is read from its folder.
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace capsflow::study {

enum class QueueState { Queued, Running };

// "12345" or "12345;cluster" (sbatch --parsable) → "12345"; nullopt when it is not a job id.
std::optional<std::string> parse_sbatch_job_id(const std::string& out);
// `squeue -h -r -o %i|%T` lines → job id ("12_3", "14") → state; states other than the waiting and
// running ones (COMPLETED, FAILED, … shown for a moment) are left out.
std::map<std::string, QueueState> parse_squeue(const std::string& out);
// `scontrol show job -o ID` → "FAILED, exit 1:0" (JobState, ExitCode); "" when not found.
std::string parse_scontrol_job(const std::string& out);

// The first line of a command's error output, without the "sbatch: error: " prefix.
std::string first_error_line(const std::string& err);

class SlurmClient {
 public:
  // Throws std::runtime_error (one line) when sbatch or squeue is not on PATH.
  SlurmClient();
  // Submits `script` (text, read by sbatch from its standard input) with `options`; returns the
  // job id. With test_only, only checks it (returns ""). Throws with sbatch's message.
  std::string submit(const std::vector<std::string>& options, const std::string& script, bool test_only) const;
  // The given jobs (array tasks as "12_3") that are still queued or running. Throws when the
  // queue cannot be read: the caller may then neither submit nor run a variant (it could run twice).
  std::map<std::string, QueueState> active(const std::vector<std::string>& job_ids) const;
  // How a job that left the queue ended, "" when slurmctld no longer knows it.
  std::string ended(const std::string& job_id) const;
  // Cancels a job (an analysis job that new variants replace); errors are ignored.
  void cancel(const std::string& job_id) const;
};

}  // namespace capsflow::study
