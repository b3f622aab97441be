#include "capsflow/core/driver/far_field_watch.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace capsflow {

void FarFieldWatch::update(const SingleLayer& bie, double t) {
  if (!enabled() || bie.far_field_checks() == seen_) return;
  seen_ = bie.far_field_checks();
  latest_ = bie.last_far_field_check();
  if (bie.worst_far_field_check().evaluation != worst_evaluation_) {
    worst_evaluation_ = bie.worst_far_field_check().evaluation;
    t_worst_ = t;
  }
  if (warned_ || bie.far_field_checks_above_tolerance() == 0) return;
  warned_ = true;  // once per run segment: the count and the worst value go to summary.json
  spdlog::warn("far-field check at t = {:g}: {} differs from direct summation by {:.2e} (max over nodes, relative to max |v|), "
               "above fluid.tolerance = {:g}{}", t, to_string(bie.backend()), bie.worst_far_field_check().max_relative, tolerance_,
               bie.fmm_order() > 0 ? fmt::format(" (FMM order {})", bie.fmm_order()) : std::string());
}

void FarFieldWatch::append_columns(io::CsvRow& row) const {
  if (!enabled()) return;
  row.emplace_back("far_field_check_max", latest_.max_relative);
  row.emplace_back("far_field_check_rms", latest_.rms_relative);
}

nlohmann::json FarFieldWatch::state(const SingleLayer& bie) const {
  // From the operator itself: a check made after the last update() (a step that then failed) counts too.
  const long checks = bie.far_field_checks();
  const double worst = checks > 0 ? bie.worst_far_field_check().max_relative : 0.0;
  const bool earlier = worst_max_before_ >= worst;
  return {{"checks", checks_before_ + checks},
          {"worst_max_relative", std::max(worst_max_before_, worst)},
          {"worst_rms_relative", std::max(worst_rms_before_, checks > 0 ? bie.worst_far_field_rms() : 0.0)},
          {"t_worst", earlier ? t_worst_before_ : t_worst_},
          {"above_tolerance", above_before_ + bie.far_field_checks_above_tolerance()}};
}

nlohmann::json FarFieldWatch::summary(const SingleLayer& bie) const {
  nlohmann::json s = state(bie);
  s.update({{"every", every_}, {"tolerance", tolerance_}, {"backend", to_string(bie.backend())}, {"fmm_order", bie.fmm_order()}});
  return s;
}

void FarFieldWatch::set_state(const nlohmann::json& s) {
  checks_before_ = s.value("checks", 0L);
  worst_max_before_ = s.value("worst_max_relative", 0.0);
  worst_rms_before_ = s.value("worst_rms_relative", 0.0);
  t_worst_before_ = s.value("t_worst", 0.0);
  above_before_ = s.value("above_tolerance", 0L);
}

}  // namespace capsflow
