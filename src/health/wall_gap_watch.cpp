#include "capsflow/core/health/wall_gap_watch.hpp"

#include <fmt/core.h>

#include <cmath>

namespace capsflow {

std::optional<HealthEvent> WallGapWatch::observe(double t, double gap) {
  if (worst_ < 0 || gap < worst_) worst_ = gap, t_worst_ = t;
  if (active_) {
    active_ = !(gap > 2 * min_gap_);  // hysteresis: one episode per approach, not per step
    return std::nullopt;
  }
  if (!(gap < min_gap_)) return std::nullopt;
  active_ = true;
  ++episodes_;
  return HealthEvent{
      HealthCondition::SurfaceGap, t,
      fmt::format("the capsule is {:.3g} wall element sizes from the channel's wall at t = {:g}, below contact.min_gap = "
                  "{:g}, the smallest gap at which the quadrature between surfaces is measured; a finer wall "
                  "(channel.element_size) resolves a thinner film (docs/channel.md §5)",
                  gap, t, min_gap_)};
}

nlohmann::json WallGapWatch::summary() const {
  const bool seen = worst_ >= 0 && std::isfinite(worst_);
  return {{"min_gap", seen ? nlohmann::json(worst_) : nlohmann::json()},
          {"t", seen ? nlohmann::json(t_worst_) : nlohmann::json()},
          {"threshold", min_gap_},
          {"episodes", episodes_},
          {"active", active_}};
}

nlohmann::json WallGapWatch::state() const {
  return {{"worst", worst_}, {"t_worst", t_worst_}, {"active", active_}, {"episodes", episodes_}};
}

void WallGapWatch::set_state(const nlohmann::json& j) {
  worst_ = j.at("worst").get<double>();
  t_worst_ = j.at("t_worst").get<double>();
  active_ = j.at("active").get<bool>();
  episodes_ = j.at("episodes").get<long>();
}

}  // namespace capsflow
