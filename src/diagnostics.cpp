#include "capsflow/core/diagnostics.hpp"

#include <cmath>
#include <fmt/core.h>
#include <limits>

namespace capsflow {

ShapeDiagnostics shape_diagnostics(const SurfaceMesh& m) {
  ShapeDiagnostics d;
  const InertiaEllipsoid e = inertia_ellipsoid(m);
  d.D = taylor_deformation(e);
  d.Le = e.semi_axes;
  d.L = half_extents(m);
  d.area = surface_area(m);
  d.volume = enclosed_volume(m);
  return d;
}

void SteadyStateDetector::add(double t, double area) {
  samples_.emplace_back(t, area);
  // Keep one sample older than t − window for the interpolation.
  while (samples_.size() > 2 && samples_[1].first <= t - window_) samples_.pop_front();
}

double SteadyStateDetector::measure() const {
  if (samples_.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto [t, s] = samples_.back();
  const double t0 = t - window_;
  if (samples_.front().first > t0 + 1e-12) return std::numeric_limits<double>::quiet_NaN();
  for (size_t i = 0; i + 1 < samples_.size(); ++i) {
    const auto [ta, sa] = samples_[i];
    const auto [tb, sb] = samples_[i + 1];
    if (ta <= t0 && t0 <= tb) {
      const double s0 = tb > ta ? sa + (sb - sa) * (t0 - ta) / (tb - ta) : sa;
      return std::abs(s - s0) / (4 * M_PI);
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

Eigen::MatrixXd SteadyStateDetector::history() const {
  Eigen::MatrixXd h(static_cast<Eigen::Index>(samples_.size()), 2);
  for (size_t i = 0; i < samples_.size(); ++i) h.row(static_cast<Eigen::Index>(i)) << samples_[i].first, samples_[i].second;
  return h;
}

void SteadyStateDetector::set_history(const Eigen::MatrixXd& h) {
  samples_.clear();
  for (Eigen::Index i = 0; i < h.rows(); ++i) samples_.emplace_back(h(i, 0), h(i, 1));
}

std::string check_health(const SurfaceMesh& before, const Points& after, double reference_volume, double max_volume_drift) {
  for (Eigen::Index i = 0; i < after.rows(); ++i)
    if (!after.row(i).allFinite()) return fmt::format("non-finite position at node {}", i);
  const Triangles& tri = before.triangles;
  for (Eigen::Index e = 0; e < tri.rows(); ++e) {
    const int a = tri(e, 0), b = tri(e, 1), c = tri(e, 2);
    const Vec3 n0 = (before.vertices.row(b) - before.vertices.row(a)).cross(before.vertices.row(c) - before.vertices.row(a));
    const Vec3 n1 = (after.row(b) - after.row(a)).cross(after.row(c) - after.row(a));
    if (n1.norm() < 1e-6 * n0.norm()) return fmt::format("element {} collapsed (area ratio {:.1e} in one step)", e, n1.norm() / n0.norm());
    if (n0.dot(n1) <= 0) return fmt::format("element {} inverted (its normal flipped in one step)", e);
  }
  SurfaceMesh m{after, tri};
  const double drift = enclosed_volume(m) / reference_volume - 1;
  if (!(std::abs(drift) <= max_volume_drift))
    return fmt::format("volume drift {:.3g} exceeds {:.3g} (runaway)", drift, max_volume_drift);
  return {};
}

}  // namespace capsflow
