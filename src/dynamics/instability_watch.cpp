#include "capsflow/core/dynamics/instability_watch.hpp"

#include <cmath>
#include <fmt/core.h>

namespace capsflow {

// Calibration (2026-11-30): the 320-element NH membrane at Ca_s = 0.05 with a fixed Heun step 1.5×
// the stability estimate drifts by 2e-7 up to γ̇t ≈ 0.15, then by ×1.27 per step; the drift passes
// 1e-6 at γ̇t ≈ 0.25 and the 1e-3 runaway check fired only at 0.43. A healthy run with the
// correction stays below 2e-7 and wanders (quick.toml: 7e-9 at γ̇t = 2; the a/b = 4 membrane:
// 6e-10). Without the correction the drift is a physical-numerical O(Δt²) error growing like a
// power of t — eight steps of ×1.15 at the start of a run — so the run loop uses the watch only
// with the correction on.
std::string InstabilityWatch::observe(double volume_drift) {
  drifts_.push_back(std::abs(volume_drift));
  if (drifts_.size() > static_cast<size_t>(kSteps) + 1) drifts_.pop_front();
  if (drifts_.size() < static_cast<size_t>(kSteps) + 1 || !(drifts_.back() > kFloor)) return {};
  for (size_t i = 1; i < drifts_.size(); ++i)
    if (!(drifts_[i] >= kFactorPerStep * drifts_[i - 1])) return {};
  const double per_step = std::pow(drifts_.back() / drifts_.front(), 1.0 / kSteps);
  return fmt::format("volume drift {:.2g} growing ×{:.2f} per step over the last {} steps (an unstable mode; a healthy run "
                     "stays near round-off)",
                     volume_drift, per_step, kSteps);
}

}  // namespace capsflow
