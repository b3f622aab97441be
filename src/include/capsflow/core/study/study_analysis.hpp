#pragma once
// The convergence analysis of a study (docs/scene-and-output.md §4.2): for each family (same
// vary values) and each observable (variant_folder.hpp), the value per level at the end of the
// run and at every output time all levels share, with the observed order and the Richardson
// extrapolation of convergence.hpp. Only finished variants enter; a family whose finest levels
// are not all finished is analysed on the longest run of consecutive finished levels ending at
// its finest finished one, and a note says so.
#include <optional>
#include <string>
#include <vector>

#include "capsflow/core/study/convergence.hpp"
#include "capsflow/core/study/study_plan.hpp"
#include "capsflow/core/study/variant_record.hpp"

namespace capsflow::study {

struct ConvergenceRow {
  std::string family, observable;
  bool final = false;  // the end of the run (summary.json) rather than an output time
  double t = 0;        // the output time; for `final`, the finest level's final time
  std::vector<int> levels;
  std::vector<double> values;  // per level
  ConvergenceEstimate estimate;
  std::string note;  // e.g. final times that differ between levels (steady-state stops)
};

struct StudyAnalysis {
  std::vector<ConvergenceRow> final_rows;  // family-major, observables in observable_names() order
  std::vector<ConvergenceRow> time_rows;   // family, then output time, then observable
  std::vector<std::string> notes;          // per family: levels left out and why
};

StudyAnalysis analyse_study(const StudyPlan& plan, const std::vector<VariantRecord>& records);

}  // namespace capsflow::study
