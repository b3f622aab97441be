#include "capsflow/core/study/study_folder.hpp"

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "capsflow/core/io/checkpoint.hpp"
#include "capsflow/core/io/folder_lock.hpp"
#include "capsflow/core/io/output_folder.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/study/study_report.hpp"
#include "capsflow/core/study/variant_folder.hpp"

namespace capsflow::study {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& msg) { throw std::runtime_error(msg); }

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

bool same_value(const nlohmann::json& a, const nlohmann::json& b) {
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    return std::abs(x - y) <= 1e-12 * std::max(std::abs(x), std::abs(y));
  }
  if (a.is_array() && b.is_array() && a.size() == b.size()) {
    for (std::size_t i = 0; i < a.size(); ++i)
      if (!same_value(a[i], b[i])) return false;
    return true;
  }
  return a == b;
}

// Refuses a variant folder holding a run of another scene (another study, or changed --set); the
// run stored its scene as written, "auto" included.
void check_same_scene(const Variant& v, const fs::path& folder, const nlohmann::json& stored) {
  const std::string diff = first_scene_difference(to_json(v.scene), stored);
  if (!diff.empty())
    fail(quoted(folder) + " holds a run of another scene (" + diff + "); pass --overwrite to run the variant " + v.name +
         " again, or choose another -o");
}

}  // namespace

void prepare_study_folder(const fs::path& dir, bool overwrite) {
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (!fs::exists(st)) {
    fs::create_directories(dir, ec);
    if (ec) fail("cannot create study folder " + quoted(dir) + ": " + ec.message());
  } else if (!fs::is_directory(st)) {
    fail("output path " + quoted(dir) + " exists and is not a folder");
  } else if (!io::is_empty_but_for_lock(dir) && !fs::exists(dir / kStudyJson, ec) && !overwrite) {
    fail("output folder " + quoted(dir) + " is not empty and holds no " + kStudyJson +
         " (not a study folder); pass --overwrite to use it anyway, or choose another -o");
  }
  io::check_writable(dir);
}

void remove_study_files(const fs::path& dir) {
  std::error_code ec;
  for (const std::string& name : study_manifest()) {
    fs::remove(dir / name, ec);
    if (ec) fail("cannot remove " + quoted(dir / name) + ": " + ec.message());
  }
}

std::string first_scene_difference(const nlohmann::json& a, const nlohmann::json& b) {
  for (const auto& [section, keys] : a.items()) {
    if (!b.contains(section)) return section;
    for (const auto& [key, value] : keys.items())
      if (!b[section].contains(key) || !same_value(b[section][key], value))
        return fmt::format("{}.{} ({} there, {} here)", section, key, b[section].contains(key) ? b[section][key].dump() : "absent",
                           value.dump());
  }
  for (const auto& [section, keys] : b.items())
    if (!a.contains(section)) return section;
  return "";
}

void check_same_study(const StudyPlan& plan, const fs::path& dir) {
  const fs::path p = dir / kStudyJson;
  std::error_code ec;
  if (!fs::exists(p, ec)) return;
  nlohmann::json stored;
  require_regular_file(p);
  try {
    std::ifstream in(p);
    stored = nlohmann::json::parse(in).at("study").at("base_scene");
  } catch (const nlohmann::json::exception&) {
    return;  // a study.json from before base_scene was recorded: the variant folders are checked one by one
  }
  // A key varied in either study (absent from its base) is not part of what both share.
  auto keep_common = [](nlohmann::json& a, const nlohmann::json& b) {
    for (auto& [section, keys] : a.items())
      if (b.contains(section))
        for (auto it = keys.begin(); it != keys.end();) it = b[section].contains(it.key()) ? std::next(it) : keys.erase(it);
  };
  nlohmann::json here = base_scene_json(plan);
  keep_common(here, stored);
  keep_common(stored, here);
  const std::string diff = first_scene_difference(here, stored);
  if (!diff.empty())
    fail(quoted(dir) + " is a study of another scene (" + diff + "); choose another -o, or pass --overwrite to run every "
         "variant anew there");
}

VariantRecord read_variant_record(const Variant& v, const fs::path& folder) {
  VariantRecord rec;
  const FolderState f = inspect_variant_folder(folder);
  if (f == FolderState::Finished || f == FolderState::Failed) {
    VariantResult r = read_variant_result(folder);
    check_same_scene(v, folder, r.summary.at("scene"));
    rec.state = f == FolderState::Finished ? VariantState::Finished : VariantState::Failed;
    rec.result = std::move(r);
  } else if (f == FolderState::Interrupted) {
    std::string scene_toml;
    try {
      scene_toml = io::read_checkpoint(io::find_latest_checkpoint(folder)).scene_toml;
    } catch (const std::runtime_error& e) {
      rec.note = fmt::format("no usable checkpoint ({}): runs again from the start", e.what());
      return rec;
    }
    check_same_scene(v, folder, to_json(parse_scene(scene_toml, "checkpoint")));
    rec.state = VariantState::Interrupted;
  }
  return rec;
}

std::vector<VariantRecord> read_variant_records(const StudyPlan& plan, const fs::path& dir) {
  std::vector<VariantRecord> records;
  for (const Variant& v : plan.variants) records.push_back(read_variant_record(v, dir / v.name));
  return records;
}

}  // namespace capsflow::study
