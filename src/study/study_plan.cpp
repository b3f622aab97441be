#include "capsflow/core/study/study_plan.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <functional>
#include <map>
#include <set>
#include <stdexcept>

#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/mesh/stats.hpp"

namespace capsflow::study {

namespace {

[[noreturn]] void fail(const std::string& msg) { throw std::runtime_error(msg); }

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

// Split on commas outside brackets and quotes.
std::vector<std::string> split_values(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  int depth = 0;
  bool quoted = false;
  for (char c : s) {
    if (c == '"') quoted = !quoted;
    if (!quoted && c == '[') ++depth;
    if (!quoted && c == ']') --depth;
    if (c == ',' && depth == 0 && !quoted) {
      out.push_back(trim(cur));
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(trim(cur));
  return out;
}

// A folder-name-safe spelling of a value: letters, digits and . + - kept, anything else '_'.
std::string safe(const std::string& v) {
  std::string out;
  for (char c : v) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '+' || c == '-') ? c : '_';
  return out.empty() ? "_" : out;
}

// Two spellings of one value (--vary flow.ca_s=0.1,1e-1) would run the same family twice: refused,
// naming both, rather than folded, so that the families are exactly the ones given.
void refuse_equal_families(const StudyPlan& plan) {
  std::map<std::string, const Variant*> seen;
  for (const Variant& v : plan.variants) {
    if (v.level != plan.levels.front()) continue;
    const auto [it, added] = seen.emplace(to_json(v.scene).dump(), &v);
    if (added) continue;
    std::string given;
    for (const VaryAxis& a : plan.vary) {
      given += " --vary " + a.key + "=";
      for (std::size_t k = 0; k < a.values.size(); ++k) given += (k ? "," : "") + a.values[k];
    }
    fail(fmt::format("--vary:{} gives the same scene twice: {} and {} (values equal as numbers or lists); give each value once",
                     given, family_label(it->second->family), family_label(v.family)));
  }
}

}  // namespace

std::vector<int> parse_levels(const std::string& text) {
  std::vector<int> levels;
  for (const std::string& item : split_values(text)) {
    std::size_t used = 0;
    int v = -1;
    try {
      v = std::stoi(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (item.empty() || used != item.size()) fail("--levels " + text + ": '" + item + "' is not an integer mesh level");
    levels.push_back(v);
  }
  std::sort(levels.begin(), levels.end());
  for (std::size_t i = 1; i < levels.size(); ++i) {
    if (levels[i] == levels[i - 1]) fail(fmt::format("--levels {}: level {} is given twice", text, levels[i]));
    if (levels[i] != levels[i - 1] + 1)
      fail(fmt::format("--levels {}: levels must be consecutive (the order estimate assumes h halves from one level to "
                       "the next; {} is missing)", text, levels[i - 1] + 1));
  }
  return levels;
}

VaryAxis parse_vary(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) fail("--vary " + text + ": expected section.key=value1,value2,...");
  VaryAxis a;
  a.key = trim(text.substr(0, eq));
  if (std::count(a.key.begin(), a.key.end(), '.') != 1 || a.key.front() == '.' || a.key.back() == '.')
    fail("--vary " + text + ": the key must be section.key (e.g. fluid.geometry)");
  if (a.key == "mesh.level") fail("--vary mesh.level: give the levels with --levels");
  a.values = split_values(text.substr(eq + 1));
  std::set<std::string> seen;
  for (const std::string& v : a.values) {
    if (v.empty()) fail("--vary " + text + ": empty value");
    if (!seen.insert(v).second) fail("--vary " + text + ": value '" + v + "' is given twice");
  }
  return a;
}

nlohmann::json base_scene_json(const StudyPlan& plan) {
  nlohmann::json j = to_json(plan.variants.front().scene);
  auto drop = [&j](const std::string& key) {
    const auto dot = key.find('.');
    if (j.contains(key.substr(0, dot))) j[key.substr(0, dot)].erase(key.substr(dot + 1));
  };
  drop("mesh.level");
  for (const VaryAxis& a : plan.vary) drop(a.key);
  return j;
}

std::string family_label(const std::string& family) { return family.empty() ? "scene" : family; }

namespace {

using SceneLoader = std::function<Scene(const std::vector<SceneOverride>&)>;

StudyPlan build_study_plan(const std::string& scene_path, const SceneLoader& load, const std::vector<std::string>& overrides,
                           const std::vector<int>& levels, const std::vector<VaryAxis>& vary) {
  StudyPlan plan;
  plan.scene_path = scene_path;
  plan.overrides = overrides;
  plan.levels = levels;
  plan.vary = vary;
  if (levels.empty()) fail("--levels: at least one mesh level is needed (three for an order)");
  for (const std::string& o : overrides)
    if (o.rfind("mesh.level=", 0) == 0) fail("--set " + o + ": a study sets mesh.level itself; give the levels with --levels");
  std::set<std::string> keys;
  for (const VaryAxis& a : vary)
    if (!keys.insert(a.key).second) fail("--vary " + a.key + ": the key is given twice");

  // Each override names the option that gave it, so that an error blames --vary or --levels.
  std::vector<SceneOverride> set;
  for (const std::string& o : overrides) set.push_back({o, "--set"});
  const Scene base = load(set);
  if (!base.mesh.file.empty())
    fail("the scene reads its mesh from mesh.file (" + base.mesh.file + "): a study refines generated meshes (mesh.level)");
  // A channel whose wall follows the capsule (element_size "auto") is refined with it, without the
  // auto rule's floor of radius/8, so that wall and capsule elements halve together from level to
  // level (docs/channel.md §5); a size given with --set or --vary is kept.
  bool refine_wall = base.channel.active() && base.channel.element_size_auto;
  for (const VaryAxis& a : vary) refine_wall = refine_wall && a.key != "channel.element_size";

  // Leaf names ("geometry") label the variants unless two axes share one (fluid.tolerance and
  // time.tolerance): then the full key.
  std::vector<std::string> labels;
  for (const VaryAxis& a : vary) {
    const std::string leaf = a.key.substr(a.key.find('.') + 1);
    bool shared = false;
    for (const VaryAxis& b : vary) shared = shared || (&a != &b && b.key.substr(b.key.find('.') + 1) == leaf);
    labels.push_back(shared ? a.key : leaf);
  }
  // Every combination of the vary values, the first axis slowest.
  std::vector<std::vector<std::pair<std::string, std::string>>> combos(1);
  for (const VaryAxis& a : vary) {
    std::vector<std::vector<std::pair<std::string, std::string>>> next;
    for (const auto& c : combos)
      for (const std::string& v : a.values) {
        auto d = c;
        d.emplace_back(a.key, v);
        next.push_back(std::move(d));
      }
    combos.swap(next);
  }
  std::set<std::string> names;
  for (const auto& c : combos) {
    std::string family;
    for (std::size_t i = 0; i < c.size(); ++i) family += (i ? "_" : "") + labels[i] + "=" + safe(c[i].second);
    plan.families.push_back(family);
  }
  for (int level : levels)
    for (std::size_t f = 0; f < combos.size(); ++f) {
      Variant v;
      v.family = plan.families[f];
      v.level = level;
      v.settings = combos[f];
      v.name = (v.family.empty() ? "" : v.family + "_") + "L" + std::to_string(level);
      if (!names.insert(v.name).second)
        fail("--vary: two variants would share the folder name '" + v.name + "' (values differing only in characters "
             "outside letters, digits and . + -)");
      std::vector<SceneOverride> given = set;
      for (const auto& [k, val] : v.settings) given.push_back({k + "=" + val, "--vary"});
      given.push_back({"mesh.level=" + std::to_string(level), "--levels"});
      v.scene = load(given);
      if (refine_wall) {  // the wall refines with the capsule: its element size is the capsule's mean edge at this level
        given.push_back({fmt::format("channel.element_size={:.6g}", mesh_stats(make_reference_mesh(v.scene.mesh)).edge_mean),
                         "--levels"});
        v.scene = load(given);
      }
      for (const SceneOverride& o : given) v.overrides.push_back(o.assignment);
      v.elements = expected_counts(v.scene.mesh.base, level).elements;
      plan.variants.push_back(std::move(v));
    }
  refuse_equal_families(plan);
  return plan;
}

}  // namespace

StudyPlan make_study_plan(const std::string& scene_path, const std::vector<std::string>& overrides,
                          const std::vector<int>& levels, const std::vector<VaryAxis>& vary) {
  if (scene_path.empty()) return make_study_plan_from_text("", default_scene_toml(), overrides, levels, vary);
  const SceneLoader load = [&](const std::vector<SceneOverride>& o) { return load_scene_with(scene_path, o); };
  return build_study_plan(scene_path, load, overrides, levels, vary);
}

StudyPlan make_study_plan_from_text(const std::string& scene_path, const std::string& scene_text,
                                    const std::vector<std::string>& overrides, const std::vector<int>& levels,
                                    const std::vector<VaryAxis>& vary) {
  const std::string name = scene_path.empty() ? std::string(kBuiltInSceneName) : scene_path;
  const SceneLoader load = [&](const std::vector<SceneOverride>& o) { return parse_scene_with(scene_text, name, o); };
  return build_study_plan(scene_path, load, overrides, levels, vary);
}

}  // namespace capsflow::study
