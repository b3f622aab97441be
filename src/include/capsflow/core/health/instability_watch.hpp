#pragma once
// Catches a numerical instability when it starts (docs/time-integration.md §5.10). An unstable mode
// multiplies everything it touches, the enclosed volume included, by the same factor |P(z)| > 1
// every step, so the volume error grows geometrically while a healthy run's does not:
//  - with the volume correction on, a healthy drift stays at round-off or at the O(Δt³) level of
//    the correction (≤ 2e-7 measured) and wanders; the watch fires once |V/V0 − 1| > kFloor and has
//    grown by at least kFactorPerStep in each of the last kSteps steps;
//  - without it, the drift is a physical-numerical error whose rate d(V/V0)/dt changes on the flow's
//    time scale; the watch fires once that rate has grown by kFactorPerStep in each of the last kSteps
//    steps, to kAboveLevel times its median over the kLevelSteps steps before, and the volume moved by
//    more than kFloor in those steps. A step length that changes by more than kSteadyStep within the
//    window would change the rate by itself (RKC's controller, clipping at outputs): such windows are
//    not judged; an unstable RKC step is caught by its error test instead.
#include <deque>
#include <string>
#include <vector>

namespace capsflow {

class InstabilityWatch {
 public:
  enum class Volume { Corrected, Uncorrected };
  static constexpr double kFloor = 1e-6;
  static constexpr double kFactorPerStep = 1.15;
  static constexpr int kSteps = 8;
  static constexpr int kLevelSteps = 32;
  static constexpr double kAboveLevel = 10;
  static constexpr double kSteadyStep = 1.1;

  explicit InstabilityWatch(Volume volume = Volume::Corrected) : volume_(volume) {}
  // The volume drift V/V0 − 1 after an accepted step of length dt. Returns "" while healthy, otherwise
  // a one-line description of the growth.
  std::string observe(double volume_drift, double dt);
  // Forget the history (after a restart: detection then needs a full history of new steps).
  void reset() {
    drifts_.clear();
    steps_.clear();
  }

 private:
  std::string observe_corrected() const;
  std::string observe_uncorrected() const;
  Volume volume_;
  std::deque<double> drifts_;  // V/V0 − 1 after each of the last steps (oldest first)
  std::deque<double> steps_;   // the matching step lengths
  mutable std::vector<double> rates_, level_;  // scratch of observe_uncorrected (no allocation per step)
};

}  // namespace capsflow
