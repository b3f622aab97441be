#include "capsflow/core/study/cost_model.hpp"

#include <algorithm>
#include <cmath>

namespace capsflow::study {

void CostModel::add(const std::string& family, long elements, double seconds) {
  if (elements > 0 && seconds > 0 && std::isfinite(seconds)) samples_.push_back({family, elements, seconds});
}

bool CostModel::fitted() const {
  for (const Sample& s : samples_)
    if (s.elements != samples_.front().elements) return true;
  return false;
}

double CostModel::exponent() const {
  if (!fitted()) return default_exponent_;
  // Least squares of log t = log c_f + β log N with one intercept per family: centre each
  // family's points on its own means, then one slope.
  double sxy = 0, sxx = 0;
  for (const Sample& s : samples_) {
    double mx = 0, my = 0;
    int n = 0;
    for (const Sample& o : samples_)
      if (o.family == s.family) mx += std::log(static_cast<double>(o.elements)), my += std::log(o.seconds), ++n;
    mx /= n;
    my /= n;
    const double dx = std::log(static_cast<double>(s.elements)) - mx;
    sxy += dx * (std::log(s.seconds) - my);
    sxx += dx * dx;
  }
  // Every family measured at one size only: no slope within a family, use the default.
  if (sxx <= 0) return default_exponent_;
  return std::clamp(sxy / sxx, kMinExponent, kMaxExponent);
}

double CostModel::predict(const std::string& family, long elements) const {
  if (samples_.empty()) return 0;
  const double beta = exponent();
  double sum = 0;
  int n = 0;
  for (int pass = 0; pass < 2 && n == 0; ++pass)  // the family's samples first, else all
    for (const Sample& s : samples_)
      if (pass == 1 || s.family == family) {
        sum += std::log(s.seconds) - beta * std::log(static_cast<double>(s.elements));
        ++n;
      }
  return std::exp(sum / n + beta * std::log(static_cast<double>(elements)));
}

CostModel study_cost_model(const StudyPlan& plan, const std::vector<VariantRecord>& records) {
  CostModel cost(is_stabilized(plan.variants.front().scene.time.scheme) ? 1.5 : 2.0);
  for (std::size_t i = 0; i < records.size(); ++i)
    if (records[i].state == VariantState::Finished && records[i].result)
      cost.add(plan.variants[i].family, records[i].result->elements, records[i].result->wall_seconds);
  return cost;
}

}  // namespace capsflow::study
