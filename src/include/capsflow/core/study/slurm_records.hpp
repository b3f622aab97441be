#pragma once
// DIR/slurm/jobs.json: which Slurm job runs (or ran) each variant of a study, so that the next
// `capsflow study` call neither submits a queued variant twice nor loses track of a failed one
// (docs/study.md §Files). Replaced atomically after every submission.
//
//   {"format": 1,
//    "variants": {"L2": {"job": "12_1", "log": "slurm/variant-12_1.out", "minutes": 10, "threads": 1,
//                        "memory_mb": 300, "submissions": 1}},
//    "analysis": {"job": "13", "log": "slurm/analyse-13.out"},
//    "submissions": [{"job": "12", "kind": "variants", "variants": ["L1", "L2"], "sbatch": [...], "at": "…"}]}
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

namespace capsflow::study {

inline constexpr const char* kSlurmFolder = "slurm";
inline constexpr const char* kSlurmJobsFile = "jobs.json";

struct VariantJob {
  std::string job;  // "12_1" (array task) or "12"
  std::string log;  // relative to the study folder
  long minutes = 0;
  int threads = 0;
  long memory_mb = 0;
  int submissions = 0;
};

struct SlurmRecords {
  std::map<std::string, VariantJob> variants;  // by variant name
  std::string analysis_job, analysis_log;
  nlohmann::json submissions = nlohmann::json::array();
};

// An absent file is no records. Throws std::runtime_error naming a malformed file.
SlurmRecords read_slurm_records(const std::filesystem::path& study_dir);
void write_slurm_records(const std::filesystem::path& study_dir, const SlurmRecords& r);

}  // namespace capsflow::study
