#pragma once
// Steady-state detection of a run (docs/time-integration.md §5.4).
#include <array>
#include <deque>
#include <limits>

#include <Eigen/Core>

namespace capsflow {

// The paper's criterion (§4.1) is the measure |S(t) − S(t − 1)| / 4πℓ² < tol, S the surface area.
// It is necessary, not sufficient: it can hold for a moment while the shape still drifts (quick.toml
// meets it at γ̇t = 1.05 with D13 = 0.1105 and ends at 0.1158 by γ̇t = 4). steady() therefore
// also asks for
//   - a minimum time of two windows (the start-up transient is over),
//   - the measure below tol at every sample of the last full window, not just now, and
//   - a plateau of the Taylor parameters: |D_ij(t) − D_ij(t − window)| < kPlateau for all ij.
class SteadyStateDetector {
 public:
  // 1e-3 in D_ij over one window: the precision the paper reports D to (three decimals).
  static constexpr double kPlateau = 1e-3;
  SteadyStateDetector(double tolerance, double window = 1.0) : tol_(tolerance), window_(window) {}
  void add(double t, double area, const std::array<double, 3>& D);
  // The paper's measure |S(t) − S(t − window)| / (4π) at the last sample, NaN before one window.
  double measure() const { return samples_.empty() ? kNaN : measure_at(samples_.size() - 1); }
  bool steady() const;
  double tolerance() const { return tol_; }
  // For checkpoints: rows (t, area, D12, D13, D23) over the last two windows.
  Eigen::MatrixXd history() const;
  void set_history(const Eigen::MatrixXd& h);  // older (t, area) rows: start afresh

 private:
  struct Sample {
    double t, area;
    std::array<double, 3> D;
  };
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double measure_at(size_t k) const;
  // Sample value interpolated at time t0 (linear), or NaN when t0 is before the first sample.
  Sample at(double t0) const;
  double tol_, window_;
  std::deque<Sample> samples_;
};

}  // namespace capsflow
