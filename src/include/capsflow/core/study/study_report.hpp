#pragma once
// The files a study writes into its folder (docs/scene-and-output.md §4.3), from the plan, the
// variants' records and the analysis: study.json (everything, for scripts/plot_study.py),
// study.csv (one row per family, observable and time, per-level columns) and study.md (the
// tables a reader wants first). Pure functions of their input, plus one writer that replaces the
// three files atomically. Missing quantities are null in JSON and empty in CSV, never NaN.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capsflow/core/study/study_analysis.hpp"

namespace capsflow::study {

inline constexpr const char* kStudyJson = "study.json";
inline constexpr const char* kStudyCsv = "study.csv";
inline constexpr const char* kStudyMarkdown = "study.md";
// The names a study writes into its own folder (what --overwrite removes there).
const std::vector<std::string>& study_manifest();

struct StudyReport {
  const StudyPlan& plan;
  const std::vector<VariantRecord>& records;
  const StudyAnalysis& analysis;
  std::string command_line;
};

nlohmann::json study_json(const StudyReport& r);
std::string study_csv(const StudyReport& r);
std::string study_markdown(const StudyReport& r);

// study.json, study.csv and study.md into `dir`, each replaced atomically.
void write_study_reports(const std::filesystem::path& dir, const StudyReport& r);

}  // namespace capsflow::study
