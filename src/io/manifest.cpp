// The names capsflow writes into an output folder (see manifest.hpp).
#include "capsflow/core/io/manifest.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdlib>

#include "capsflow/core/io/channel_wall_file.hpp"
#include "capsflow/core/io/checkpoint.hpp"
#include "capsflow/core/io/folder_lock.hpp"
#include "capsflow/core/io/results_writer.hpp"

namespace capsflow::io {

namespace {
constexpr const char* kProbePrefix = ".capsflow-write-probe.";
}

const std::vector<std::string>& output_manifest() {
  static const std::vector<std::string> names = {
      kRunH5, kRunXdmf, kTimeseriesCsv, kSummaryJson, kCheckpointFile,
      previous_checkpoint_path(kCheckpointFile).string(), kChannelH5, kChannelXdmf};
  return names;
}

bool is_capsflow_temporary_name(const std::string& name, long* pid) {
  std::string base, digits;
  const std::string probe = kProbePrefix;
  if (name.compare(0, probe.size(), probe) == 0) {
    digits = name.substr(probe.size());
  } else {
    const std::size_t tmp = name.rfind(".tmp.");
    if (tmp == std::string::npos) return false;
    base = name.substr(0, tmp);
    digits = name.substr(tmp + 5);
    const auto& m = output_manifest();
    if (std::find(m.begin(), m.end(), base) == m.end()) return false;
  }
  if (digits.empty() || digits.size() > 9 ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return false;
  if (pid != nullptr) *pid = std::strtol(digits.c_str(), nullptr, 10);
  return true;
}

bool is_capsflow_output_name(const std::string& name) {
  const auto& m = output_manifest();
  return std::find(m.begin(), m.end(), name) != m.end() || is_capsflow_temporary_name(name);
}

bool is_run_folder_name(const std::string& name) { return is_capsflow_output_name(name) || name == kFolderLockFile; }

}  // namespace capsflow::io
