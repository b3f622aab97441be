#pragma once
// The study folder DIR (docs/scene-and-output.md §4.1): made ready for a study, and read back —
// what each variant's folder holds, as the study's records, whoever ran it (this process, a
// --jobs child, a Slurm job). A variant folder or a study.json of another scene is refused with
// one line before anything is written.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capsflow/core/study/study_plan.hpp"
#include "capsflow/core/study/variant_record.hpp"

namespace capsflow::study {

// New, empty, or holding study.json (a study to continue); with overwrite, any folder. Throws
// std::runtime_error (one line).
void prepare_study_folder(const std::filesystem::path& dir, bool overwrite);
// --overwrite: removes the study files (the variants are run anew); nothing else. Called once
// nothing can refuse the study any more (a Slurm submission is checked first).
void remove_study_files(const std::filesystem::path& dir);

// The first key (section.key, with both values) whose value differs between two resolved scenes
// (to_json), "" if none; numbers equal to 1e-12 relative (a scene that went through a
// checkpoint's TOML has its derived numbers recomputed, possibly one rounding apart).
std::string first_scene_difference(const nlohmann::json& here, const nlohmann::json& there);

// Refuses (throws) when DIR's study.json records another base scene (study_plan.hpp): a study
// folder of another scene. Keys varied in either study are not compared.
void check_same_study(const StudyPlan& plan, const std::filesystem::path& dir);

// One record per variant from its folder: finished and failed ones with their results (after
// checking that they ran this variant's scene), interrupted ones whose checkpoint is usable,
// pending otherwise. Throws on a folder of another scene.
std::vector<VariantRecord> read_variant_records(const StudyPlan& plan, const std::filesystem::path& dir);
VariantRecord read_variant_record(const Variant& v, const std::filesystem::path& folder);

}  // namespace capsflow::study
