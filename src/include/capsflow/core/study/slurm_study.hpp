#pragma once
// `capsflow study … --scheduler slurm` (docs/study.md §Slurm): submit and collect.
//
// Each call reads the queue (squeue) for the jobs DIR/slurm/jobs.json records, then each
// variant's folder: a variant whose job is queued or running is left alone (never submitted
// twice); a finished one is read; one that stopped numerically is reported and left, as locally;
// one whose job ended without a result (it failed: an I/O error, killed before its first
// checkpoint, a node failure) is reported with the job's state and its log's last error line, and
// submitted again; one that stopped with a checkpoint (its time limit: SIGTERM 120 s before it)
// is submitted again with at least twice the time limit, and continues from its checkpoint.
// The variants to submit are grouped by size (slurm_sizing.hpp): one array job per group, every
// group checked first with `sbatch --test-only`, so a refused site option or resource submits
// nothing. Then one analysis job, `--dependency=afterany` on every variant job of the study, runs
// `capsflow study --analyse DIR`. When nothing is left to run, the call analyses in place.
#include <filesystem>
#include <vector>

#include "capsflow/core/study/study_runner.hpp"
#include "capsflow/core/study/variant_record.hpp"

namespace capsflow::study {

// Before anything is written: sbatch and squeue on PATH, the site options well formed.
void check_slurm_submission(const StudyOptions& o);

// Exit code: 0 submitted, or nothing left to submit; with nothing queued or running, as a local
// study (0 or 3). Throws std::runtime_error (one line) when Slurm refuses.
int submit_study(const StudyPlan& plan, const StudyOptions& o, std::vector<VariantRecord>& records);

// For --analyse: each variant without a result whose job is still queued or running (squeue,
// when Slurm is reachable from here) is queued / running; any other with a job gets the job and
// its log's last error line.
void annotate_from_slurm_records(const StudyPlan& plan, const std::filesystem::path& dir, std::vector<VariantRecord>& records);

// For the local scheduler: refuses (one line) while jobs of a Slurm study in DIR are queued or
// running, as they would write the same variant folders. Without Slurm on PATH (a study folder
// copied off the cluster) there is nothing to ask and nothing is refused.
void refuse_while_slurm_jobs_active(const std::filesystem::path& dir);

}  // namespace capsflow::study
