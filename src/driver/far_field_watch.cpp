#include "capsflow/core/driver/far_field_watch.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace capsflow {

void FarFieldWatch::update(const FarFieldCheckLog& log, const char* backend, int fmm_order, double t) {
  if (!enabled() || log.checks == seen_) return;
  seen_ = log.checks;
  latest_ = log.last;
  if (log.worst.evaluation != worst_evaluation_) {
    worst_evaluation_ = log.worst.evaluation;
    t_worst_ = t;
  }
  if (warned_ || log.above_tolerance == 0) return;
  warned_ = true;  // once per run segment: the count and the worst value go to summary.json
  spdlog::warn("{} at t = {:g}: {} differs from direct summation by {:.2e} (max over nodes, relative to {}), "
               "above fluid.tolerance = {:g}{}", label_, t, backend, log.worst.max_relative, scale_, tolerance_,
               fmm_order > 0 ? fmt::format(" (FMM order {})", fmm_order) : std::string());
}

void FarFieldWatch::append_columns(io::CsvRow& row) const {
  if (!enabled()) return;
  row.emplace_back(name_ + "_max", latest_.max_relative);
  row.emplace_back(name_ + "_rms", latest_.rms_relative);
}

nlohmann::json FarFieldWatch::state(const FarFieldCheckLog& log) const {
  // From the operator itself: a check made after the last update() (a step that then failed) counts too.
  const long checks = log.checks;
  const double worst = checks > 0 ? log.worst.max_relative : 0.0;
  const bool earlier = worst_max_before_ >= worst;
  return {{"checks", checks_before_ + checks},
          {"worst_max_relative", std::max(worst_max_before_, worst)},
          {"worst_rms_relative", std::max(worst_rms_before_, checks > 0 ? log.worst_rms : 0.0)},
          {"t_worst", earlier ? t_worst_before_ : t_worst_},
          {"above_tolerance", above_before_ + log.above_tolerance}};
}

void FarFieldWatch::set_state(const nlohmann::json& s) {
  checks_before_ = s.value("checks", 0L);
  worst_max_before_ = s.value("worst_max_relative", 0.0);
  worst_rms_before_ = s.value("worst_rms_relative", 0.0);
  t_worst_before_ = s.value("t_worst", 0.0);
  above_before_ = s.value("above_tolerance", 0L);
}

}  // namespace capsflow
