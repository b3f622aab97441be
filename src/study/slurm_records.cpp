#include "capsflow/core/study/slurm_records.hpp"

#include <fstream>
#include <stdexcept>

#include "capsflow/core/io/atomic_file.hpp"
#include "capsflow/core/study/variant_folder.hpp"

namespace capsflow::study {
namespace fs = std::filesystem;

SlurmRecords read_slurm_records(const fs::path& dir) {
  SlurmRecords r;
  const fs::path p = dir / kSlurmFolder / kSlurmJobsFile;
  std::error_code ec;
  if (!fs::exists(p, ec)) return r;
  require_regular_file(p);
  std::ifstream in(p);
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    for (const auto& [name, v] : j.at("variants").items())
      r.variants[name] = {v.at("job").get<std::string>(), v.at("log").get<std::string>(), v.at("minutes").get<long>(),
                          v.at("threads").get<int>(), v.at("memory_mb").get<long>(), v.at("submissions").get<int>()};
    if (j.contains("analysis")) {
      r.analysis_job = j["analysis"].at("job").get<std::string>();
      r.analysis_log = j["analysis"].at("log").get<std::string>();
    }
    r.submissions = j.value("submissions", nlohmann::json::array());
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error("'" + p.string() + "' is not a capsflow job record (" + e.what() + ")");
  }
  return r;
}

void write_slurm_records(const fs::path& dir, const SlurmRecords& r) {
  nlohmann::json j = {{"format", 1}, {"variants", nlohmann::json::object()}, {"submissions", r.submissions}};
  for (const auto& [name, v] : r.variants)
    j["variants"][name] = {{"job", v.job}, {"log", v.log}, {"minutes", v.minutes}, {"threads", v.threads},
                           {"memory_mb", v.memory_mb}, {"submissions", v.submissions}};
  if (!r.analysis_job.empty()) j["analysis"] = {{"job", r.analysis_job}, {"log", r.analysis_log}};
  std::error_code ec;
  fs::create_directories(dir / kSlurmFolder, ec);
  if (ec) throw std::runtime_error("cannot create '" + (dir / kSlurmFolder).string() + "': " + ec.message());
  io::write_file_atomically(dir / kSlurmFolder / kSlurmJobsFile, j.dump(2) + "\n");
}

}  // namespace capsflow::study
