#pragma once
// Shape diagnostics at an output time (paper Eq. 40, Table 1) and run-health checks.
#include <deque>
#include <string>
#include <utility>

#include "capsflow/core/geometry.hpp"

namespace capsflow {

struct ShapeDiagnostics {
  TaylorDeformation D;
  Vec3 Le = Vec3::Zero();  // inertia-ellipsoid semi-axes
  Vec3 L = Vec3::Zero();   // half-extents of the surface
  double area = 0, volume = 0;
};
ShapeDiagnostics shape_diagnostics(const SurfaceMesh& current);

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

// Early detection of a failing run (numerics pitfalls 15, 17): non-finite positions, an element
// whose normal flipped during the step (inversion), a collapsed element, or runaway volume.
// Returns an empty string when healthy, otherwise a one-line description.
std::string check_health(const SurfaceMesh& before, const Points& after, double reference_volume,
                         double max_volume_drift = 0.05);

}  // namespace capsflow
