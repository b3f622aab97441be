#include "capsflow/core/health/surface_gap_watch.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace capsflow {

namespace {
nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }
double from_json_or_inf(const nlohmann::json& j) { return j.is_null() ? SurfaceGap::kNone : j.get<double>(); }
}  // namespace

std::optional<HealthEvent> SurfaceGapWatch::observe(double t, const SurfaceGap& closest) {
  last_ = closest;
  if (closest.ratio < worst_.ratio) {
    worst_ = closest;
    t_worst_ = t;
  }
  if (active_) {
    active_ = !(closest.ratio > 2 * min_gap_);  // hysteresis: one episode per approach, not per step
    return std::nullopt;
  }
  if (!(closest.ratio < min_gap_)) return std::nullopt;
  active_ = true;
  ++episodes_;
  const SurfacePart& p = parts_.at(static_cast<std::size_t>(closest.part));
  const SurfacePart& o = parts_.at(static_cast<std::size_t>(closest.other));
  return HealthEvent{
      HealthCondition::SurfaceGap, t,
      fmt::format("capsules {} and {} are {:.3g} element sizes apart at t = {:g} (node {} of capsule {}, element {} of capsule "
                  "{}), below contact.min_gap = {:g}, the smallest gap at which the quadrature between surfaces is measured; "
                  "contact.repulsion_range (e.g. 1) keeps capsules apart, a finer mesh resolves a thinner film "
                  "(docs/several-capsules.md)",
                  closest.part + 1, closest.other + 1, closest.ratio, t, closest.node - p.node_begin, closest.part + 1,
                  closest.element - o.element_begin, closest.other + 1, min_gap_)};
}

std::vector<std::pair<std::string, double>> SurfaceGapWatch::columns() const {
  const bool near = std::isfinite(last_.ratio);
  return {{"surface_gap", last_.ratio},
          {"gap_capsule_a", near ? std::min(last_.part, last_.other) + 1 : 0},
          {"gap_capsule_b", near ? std::max(last_.part, last_.other) + 1 : 0}};
}

nlohmann::json SurfaceGapWatch::summary() const {
  const bool near = std::isfinite(worst_.ratio);
  return {{"min_gap", finite_or_null(worst_.ratio)},
          {"t", near ? nlohmann::json(t_worst_) : nlohmann::json()},
          {"capsules", near ? nlohmann::json{std::min(worst_.part, worst_.other) + 1, std::max(worst_.part, worst_.other) + 1}
                         : nlohmann::json()},
          {"threshold", min_gap_},
          {"episodes", episodes_},
          {"active", active_}};
}

nlohmann::json SurfaceGapWatch::state() const {
  return {{"worst", finite_or_null(worst_.ratio)}, {"worst_part", worst_.part}, {"worst_other", worst_.other},
          {"t_worst", t_worst_}, {"active", active_}, {"episodes", episodes_}};
}

void SurfaceGapWatch::set_state(const nlohmann::json& j) {
  worst_.ratio = from_json_or_inf(j.at("worst"));
  worst_.part = j.at("worst_part").get<int>();
  worst_.other = j.at("worst_other").get<int>();
  t_worst_ = j.at("t_worst").get<double>();
  active_ = j.at("active").get<bool>();
  episodes_ = j.at("episodes").get<long>();
}

}  // namespace capsflow
