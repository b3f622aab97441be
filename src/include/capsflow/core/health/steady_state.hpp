#pragma once
// Steady-state detection of a run (docs/time-integration.md §5.11).
#include <array>
#include <deque>
#include <limits>

#include <Eigen/Core>

#include "capsflow/core/geometry/taylor_deformation.hpp"

namespace capsflow {

// The inertia ellipsoid as one label-free tensor: A = Σ_i Le_i a_i a_iᵀ (a_i its principal
// directions) divided by (Le1 + Le2 + Le3)/3, as its six components (11, 12, 13, 22, 23, 33). Unlike
// D_ij, whose axes are labelled by the coordinate axis each is most aligned with, A changes when the
// shape turns, whatever its labels do.
using ShapeTensor = std::array<double, 6>;
ShapeTensor shape_tensor(const InertiaEllipsoid& e);

// The paper's criterion (§4.1) is the measure |S(t) − S(t − 1)| / 4πℓ² < tol, S the surface area.
// It is necessary, not sufficient: it can hold for a moment while the shape still drifts (quick.toml
// meets it at γ̇t = 1.05 with D13 = 0.1105 and ends at 0.1158 by γ̇t = 4), and it cannot see a shape
// that turns (a tumbling disc keeps its area). steady() therefore also asks for
//   - a minimum time of two windows (the start-up transient is over),
//   - the measure below tol at every sample of the last full window, not just now,
//   - a plateau of the Taylor parameters: |D_ij(t) − D_ij(t − window)| < kPlateau for all ij, and
//   - a plateau of the shape tensor, orientation included: |A_ij(t) − A_ij(t − s)| < 2 kPlateau for
//     all ij, at s = window and s = window/2 (a rotation by half a turn leaves A unchanged: with two
//     lags a turning shape passes only if it made a half-turn in window/2 and in window at once).
class SteadyStateDetector {
 public:
  // 1e-3 in D_ij over one window: the precision the paper reports D to (three decimals).
  static constexpr double kPlateau = 1e-3;
  // The shape tensor's tolerance, 2 kPlateau: a change ε of one semi-axis (Le ≈ 1) changes D_ij by
  // ε/2 and A by ε, so the same change of shape meets both tests at once; a turn by δθ (radians)
  // changes A_12 by about 2 D δθ.
  static constexpr double kTensorPlateau = 2 * kPlateau;
  SteadyStateDetector(double tolerance, double window = 1.0) : tol_(tolerance), window_(window) {}
  void add(double t, double area, const std::array<double, 3>& D, const ShapeTensor& A);
  // The same from the inertia ellipsoid (D_ij and A computed from it).
  void add(double t, double area, const InertiaEllipsoid& e);
  // The paper's measure |S(t) − S(t − window)| / (4π) at the last sample, NaN before one window.
  double measure() const { return samples_.empty() ? kNaN : measure_at(samples_.size() - 1); }
  bool steady() const;
  double tolerance() const { return tol_; }
  // For checkpoints: rows (t, area, D12, D13, D23, A11, A12, A13, A22, A23, A33) over the last two windows.
  Eigen::MatrixXd history() const;
  void set_history(const Eigen::MatrixXd& h);  // older rows without A (or without D): start afresh

 private:
  struct Sample {
    double t, area;
    std::array<double, 3> D;
    ShapeTensor A;
  };
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double measure_at(size_t k) const;
  // Sample value interpolated at time t0 (linear), or NaN when t0 is before the first sample.
  Sample at(double t0) const;
  double tol_, window_;
  std::deque<Sample> samples_;
};

}  // namespace capsflow
