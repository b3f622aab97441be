#pragma once
// Steady-state detection of a run (paper §4.1 criterion; docs/time-integration.md §5.4).
#include <deque>
#include <utility>

#include <Eigen/Core>

namespace capsflow {

// Paper §4.1: steady when the surface area changed by less than tol·4πℓ² over γ̇t = 1.
// Samples are (t, area) pairs at every step; the area at t − window is interpolated linearly.
class SteadyStateDetector {
 public:
  SteadyStateDetector(double tolerance, double window = 1.0) : tol_(tolerance), window_(window) {}
  void add(double t, double area);
  // |S(t) − S(t − window)| / (4π), NaN before one window has elapsed.
  double measure() const;
  bool steady() const { return measure() < tol_; }
  double tolerance() const { return tol_; }
  // For checkpoints: rows (t, area).
  Eigen::MatrixXd history() const;
  void set_history(const Eigen::MatrixXd& h);

 private:
  double tol_, window_;
  std::deque<std::pair<double, double>> samples_;
};

}  // namespace capsflow
