#include "capsflow/core/health/instability_watch.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/core.h>

namespace capsflow {

// Calibration (2026-11-30), the 320-element NH membrane at Ca_s = 0.05 with a fixed Heun step 1.5×
// the stability estimate:
//  - corrected: the drift stays at 2e-7 up to γ̇t ≈ 0.15, then grows ×1.27 per step; it passes 1e-6
//    at γ̇t ≈ 0.25 and the 1e-3 runaway check fired only at 0.43. A healthy corrected run stays below
//    2e-7 and wanders (quick.toml: 7e-9 at γ̇t = 2; the a/b = 4 membrane: 6e-10). An uncorrected
//    drift grows like a power of t — eight steps of ×1.15 at the start of a run — hence two rules.
//  - uncorrected: the physical drift rate is ≈ 5e-4 per unit time; the instability saturates in
//    grid-scale folds (facet normals 60–75° apart) and the run used to reach t_end with −3.6 % volume
//    and exit 0 (the 5 % runaway check never fired).
std::string InstabilityWatch::observe(double volume_drift, double dt) {
  drifts_.push_back(volume_drift);
  steps_.push_back(dt);
  const size_t keep = volume_ == Volume::Corrected ? kSteps + 1 : kLevelSteps + kSteps + 2;
  while (drifts_.size() > keep) {
    drifts_.pop_front();
    steps_.pop_front();
  }
  if (drifts_.size() < keep) return {};
  return volume_ == Volume::Corrected ? observe_corrected() : observe_uncorrected();
}

std::string InstabilityWatch::observe_corrected() const {
  if (!(std::abs(drifts_.back()) > kFloor)) return {};
  for (size_t i = 1; i < drifts_.size(); ++i)
    if (!(std::abs(drifts_[i]) >= kFactorPerStep * std::abs(drifts_[i - 1]))) return {};
  const double per_step = std::pow(std::abs(drifts_.back() / drifts_.front()), 1.0 / kSteps);
  return fmt::format("volume drift {:.2g} growing ×{:.2f} per step over the last {} steps (an unstable mode; a healthy run "
                     "stays near round-off)",
                     drifts_.back(), per_step, kSteps);
}

std::string InstabilityWatch::observe_uncorrected() const {
  // rates[i] = |d(V/V0)/dt| over step i + 1; the last kSteps + 1 form the window, the kLevelSteps
  // before it the running level.
  std::vector<double>& rates = rates_;
  rates.clear();
  for (size_t i = 1; i < drifts_.size(); ++i) rates.push_back(std::abs(drifts_[i] - drifts_[i - 1]) / steps_[i]);
  const size_t first = rates.size() - (kSteps + 1);
  const auto [shortest, longest] = std::minmax_element(steps_.begin() + static_cast<long>(first) + 1, steps_.end());
  if (*longest > kSteadyStep * *shortest) return {};
  if (!(std::abs(drifts_.back() - drifts_[first]) > kFloor)) return {};
  for (size_t i = first + 1; i < rates.size(); ++i)
    if (!(rates[i] >= kFactorPerStep * rates[i - 1])) return {};
  std::vector<double>& level = level_;
  level.assign(rates.begin(), rates.begin() + static_cast<long>(first));
  std::nth_element(level.begin(), level.begin() + static_cast<long>(level.size() / 2), level.end());
  const double median = level[level.size() / 2];
  if (!(rates.back() > kAboveLevel * median)) return {};
  const double per_step = std::pow(rates.back() / rates[first], 1.0 / kSteps);
  return fmt::format("volume drift rate {:.2g} per unit time, {:.0f}× its running level, growing ×{:.2f} per step over the "
                     "last {} steps (an unstable mode; volume drift now {:.2g})",
                     rates.back(), rates.back() / median, per_step, kSteps, drifts_.back());
}

}  // namespace capsflow
