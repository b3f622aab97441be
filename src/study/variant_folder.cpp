#include "capsflow/core/study/variant_folder.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "capsflow/core/io/checkpoint.hpp"
#include "capsflow/core/io/input_file.hpp"
#include "capsflow/core/io/manifest.hpp"
#include "capsflow/core/io/results_writer.hpp"

namespace capsflow::study {
namespace fs = std::filesystem;

namespace {

nlohmann::json read_json(const fs::path& p) {
  require_regular_file(p);
  std::ifstream in(p);
  if (!in) throw std::runtime_error("cannot read '" + p.string() + "'");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error("'" + p.string() + "' is not valid JSON: " + e.what());
  }
}

StopReason stop_reason_of(const nlohmann::json& summary, const fs::path& file) {
  const auto text = summary.find("stop_reason");
  const std::optional<StopReason> stop =
      text != summary.end() && text->is_string() ? StopReason::parse(text->get<std::string>()) : std::nullopt;
  if (!stop)
    throw std::runtime_error("'" + file.string() + "': stop_reason " + (text == summary.end() ? "missing" : text->dump()) +
                             " is not one this capsflow writes");
  return *stop;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();  // an empty last field (a rate not defined yet)
  return out;
}

}  // namespace

void require_regular_file(const fs::path& p) {
  std::error_code ec;
  if (!fs::exists(p, ec)) return;  // the reader says what a missing file means
  if (const std::string problem = io::input_file_problem(p.string(), io::kAnyFileSize); !problem.empty())
    throw std::runtime_error("cannot read '" + p.string() + "': it " + problem);
}

FolderState inspect_variant_folder(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec) || fs::is_empty(dir, ec)) return FolderState::Empty;
  const fs::path summary = dir / io::kSummaryJson;
  if (fs::exists(summary, ec)) {
    const StopReason stop = stop_reason_of(read_json(summary), summary);
    return stop.finished() ? FolderState::Finished
           : stop.kind() == StopKind::Interrupted ? FolderState::Interrupted
                                                   : FolderState::Failed;
  }
  const fs::path ck = dir / io::kCheckpointFile;
  if (fs::exists(ck, ec) || fs::exists(io::previous_checkpoint_path(ck), ec)) return FolderState::Interrupted;
  bool has_run_files = false;
  for (const auto& e : fs::directory_iterator(dir, ec)) has_run_files = has_run_files || io::is_capsflow_output_name(e.path().filename().string());
  return has_run_files ? FolderState::Unfinished : FolderState::Empty;
}

const std::vector<std::string>& observable_names() {
  static const std::vector<std::string> names = {"D12", "D13", "D23", "L1", "L2", "L3", "Le1", "Le2", "Le3", "area", "volume_drift"};
  return names;
}

const std::vector<std::string>& channel_observable_names() {
  static const std::vector<std::string> names = {"velocity_ratio", "pressure_drop"};
  return names;
}

namespace {
// A run of several capsules (docs/several-capsules.md): a study's observables are capsule 1's.
bool several_capsules(const nlohmann::json& summary) {
  return summary.contains("capsules") && summary.at("capsules").size() > 1;
}
const nlohmann::json& capsule_one(const nlohmann::json& summary) {
  return several_capsules(summary) ? summary.at("capsules").at(0) : summary;
}
}  // namespace

VariantResult read_variant_result(const fs::path& dir) {
  VariantResult r;
  const fs::path sp = dir / io::kSummaryJson;
  r.summary = read_json(sp);
  const nlohmann::json& s = r.summary;
  r.stop = stop_reason_of(s, sp);
  try {
    r.t_final = s.at("t").get<double>();
    r.elements = s.at("elements").get<long>();
    r.nodes = s.at("nodes").get<long>();
    r.wall_seconds = s.at("wall_seconds").get<double>();
    r.rhs_evaluations = s.value("rhs_evaluations", 0L);
    r.peak_rss_mb = s.value("peak_rss_mb", 0.0);
    const nlohmann::json& timing = s.at("timing");
    r.seconds_per_evaluation = timing.at("seconds_per_evaluation").get<double>();
    const double evals = timing.at("rhs_evaluations").get<double>();
    for (const auto& [phase, seconds] : timing.at("phases").items())
      r.seconds_per_evaluation_by_phase[phase] = evals > 0 ? seconds.get<double>() / evals : 0.0;
    const nlohmann::json& c = capsule_one(s);
    for (const char* k : {"D12", "D13", "D23", "area", "volume_drift"}) r.final_values[k] = c.at(k).get<double>();
    for (int i = 0; i < 3; ++i) {
      r.final_values["L" + std::to_string(i + 1)] = c.at("L").at(i).get<double>();
      r.final_values["Le" + std::to_string(i + 1)] = c.at("Le").at(i).get<double>();
    }
    if (s.contains("channel"))
      for (const std::string& k : channel_observable_names()) r.final_values[k] = s.at(k).get<double>();
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error("'" + sp.string() + "': missing or malformed key (" + e.what() + ")");
  }
  const fs::path cp = dir / io::kTimeseriesCsv;
  require_regular_file(cp);
  std::ifstream in(cp);
  if (!in) throw std::runtime_error("cannot read '" + cp.string() + "'");
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = split(line);
  std::map<std::string, std::size_t> column;
  for (std::size_t i = 0; i < header.size(); ++i) column[header[i]] = i;
  if (!column.count("t")) throw std::runtime_error("'" + cp.string() + "': no column 't'");
  const std::string prefix = several_capsules(s) ? "c1." : "";  // the observables are capsule 1's
  std::vector<std::string> names = observable_names();
  if (s.contains("channel")) names.insert(names.end(), channel_observable_names().begin(), channel_observable_names().end());
  for (const std::string& name : names)
    if (!column.count(prefix + name)) throw std::runtime_error("'" + cp.string() + "': no column '" + prefix + name + "'");
  while (std::getline(in, line)) {
    const std::vector<std::string> cells = split(line);
    if (cells.size() != header.size()) continue;  // a line cut by a crash
    auto cell = [&](const std::string& name) { return std::strtod(cells[column.at(name)].c_str(), nullptr); };
    r.times.push_back(cell("t"));
    for (const std::string& name : names) r.series[name].push_back(cell(prefix + name));
  }
  return r;
}

}  // namespace capsflow::study
