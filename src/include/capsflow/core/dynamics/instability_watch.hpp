#pragma once
// Catches a numerical instability when it starts (docs/time-integration.md §5.3): with the volume
// correction on, a healthy run's volume drift stays at round-off or at the O(Δt³) level of the
// correction (≤ 2e-7 measured on Heun runs, 1e-14 with RKC's projection), and it wanders. An
// unstable mode instead multiplies everything it touches, the volume included, by the same factor
// |P(z)| > 1 every step: the drift then grows geometrically. The watch stops the run once the drift
// is above kFloor and has grown by at least kFactorPerStep in each of the last kSteps steps — long
// before the 1e-3 runaway check of check_health (measured in the comment of instability_watch.cpp).
#include <deque>
#include <string>

namespace capsflow {

class InstabilityWatch {
 public:
  static constexpr double kFloor = 1e-6;
  static constexpr double kFactorPerStep = 1.15;
  static constexpr int kSteps = 8;

  // The volume drift V/V0 − 1 after an accepted step. Returns "" while healthy, otherwise a one-line
  // description of the growth.
  std::string observe(double volume_drift);
  // Forget the history (after a restart: detection then needs kSteps new steps).
  void reset() { drifts_.clear(); }

 private:
  std::deque<double> drifts_;  // |drift| of the last kSteps + 1 steps
};

}  // namespace capsflow
