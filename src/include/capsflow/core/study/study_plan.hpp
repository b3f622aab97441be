#pragma once
// The variants of a convergence study (`capsflow study`, docs/scene-and-output.md §4): every
// mesh level of --levels crossed with every combination of the --vary values. A variant is an
// ordinary run of the scene with --set overrides: the study's own --set first, then the vary
// values, then mesh.level. A family is the variants with the same vary values (all levels): the
// unit of the convergence analysis.
//
// Everything is validated before anything runs (a typo must not surface after hours): the levels
// (integers, no repeats, consecutive — the order estimate assumes h halves per level), the vary
// axes (key=v1,v2,..., no mesh.level, no repeated key) and every variant's scene.
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "capsflow/core/scene/scene.hpp"

namespace capsflow::study {

// The scene name recorded for a study of the built-in default scene.
inline constexpr const char* kBuiltInSceneName = "<built-in default>";

struct VaryAxis {
  std::string key;                  // section.key
  std::vector<std::string> values;  // as given (TOML values or bare strings, like --set)
};

struct Variant {
  std::string name;    // folder name under the study folder, e.g. "geometry=curved_L4" or "L4"
  std::string family;  // e.g. "geometry=curved"; "" without --vary
  int level = 0;
  std::vector<std::pair<std::string, std::string>> settings;  // the vary key and value of each axis
  std::vector<std::string> overrides;                         // every --set of this run
  Scene scene;
  long elements = 0;  // of the generated mesh
};

struct StudyPlan {
  std::string scene_path;               // "" = the built-in default scene
  std::vector<std::string> overrides;   // the study's --set
  std::vector<int> levels;              // ascending, consecutive
  std::vector<VaryAxis> vary;
  std::vector<std::string> families;    // in --vary order
  std::vector<Variant> variants;        // coarse to fine; within a level, in family order
};

// "3,4,5" → {3, 4, 5} (sorted). Throws std::runtime_error naming --levels.
std::vector<int> parse_levels(const std::string& text);
// "fluid.geometry=flat,curved" → {fluid.geometry, {flat, curved}}. Commas inside [...] or "..."
// belong to the value. Throws std::runtime_error naming --vary.
VaryAxis parse_vary(const std::string& text);

// Builds and validates every variant. Throws SceneError / std::runtime_error (one line).
StudyPlan make_study_plan(const std::string& scene_path, const std::vector<std::string>& overrides,
                          const std::vector<int>& levels, const std::vector<VaryAxis>& vary);
// The same from the scene file's text as a study recorded it (study.json's `study.scene_text`), so
// that `study --analyse` needs neither the file nor the folder the study was started from.
StudyPlan make_study_plan_from_text(const std::string& scene_path, const std::string& scene_text,
                                    const std::vector<std::string>& overrides, const std::vector<int>& levels,
                                    const std::vector<VaryAxis>& vary);

// The scene every variant shares: the scene file with the study's --set, mesh.level and the vary
// keys left out (to_json form; study.json's `study.base_scene`).
nlohmann::json base_scene_json(const StudyPlan& plan);

// "geometry=curved" (the family label used in reports; "scene" without --vary).
std::string family_label(const std::string& family);

}  // namespace capsflow::study
