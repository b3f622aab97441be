#pragma once
// The study's ETA: wall time per variant modelled as c·N^β in the element count N, fitted to the
// variants measured so far. β is the least-squares slope of log(time) against log(N) once two
// sizes are measured (clamped to [1, 3]: below 1 a run would get cheaper per element as it
// grows, above 3 the fit is following noise); until then the expected growth of the scheme:
// cost per evaluation ∝ N (FMM) times the number of evaluations, ∝ 1/Δt ∝ N for Heun (membrane
// stability limit Δt ∝ h², docs/time-integration.md §5.9) and ∝ √ρ ∝ N^0.5 for RKC, i.e.
// β = 2 (Heun) or 1.5 (RKC). c comes from the same family's measurements when there are any,
// else from all (families differ by constant factors such as curved/flat ≈ 1.5).
#include <string>
#include <vector>

#include "capsflow/core/study/study_plan.hpp"
#include "capsflow/core/study/variant_record.hpp"

namespace capsflow::study {

class CostModel {
 public:
  explicit CostModel(double default_exponent) : default_exponent_(default_exponent) {}

  void add(const std::string& family, long elements, double seconds);
  // Predicted seconds of a variant of `family` with `elements`; 0 when nothing is measured yet.
  double predict(const std::string& family, long elements) const;
  double exponent() const;  // the fitted β, or the default
  bool fitted() const;      // two or more sizes measured

  static constexpr double kMinExponent = 1.0, kMaxExponent = 3.0;

 private:
  struct Sample {
    std::string family;
    long elements;
    double seconds;
  };
  double default_exponent_;
  std::vector<Sample> samples_;
};

// The model of a study: the scheme's default exponent, fitted to its finished variants.
CostModel study_cost_model(const StudyPlan& plan, const std::vector<VariantRecord>& records);

}  // namespace capsflow::study
