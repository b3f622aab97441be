#include "capsflow/core/health/steady_state.hpp"

#include <cmath>
#include <limits>

namespace capsflow {

void SteadyStateDetector::add(double t, double area, const std::array<double, 3>& D) {
  samples_.push_back({t, area, D});
  // Keep two windows (and one sample before) so the measure can be checked over the last window.
  while (samples_.size() > 2 && samples_[1].t <= t - 2 * window_) samples_.pop_front();
}

SteadyStateDetector::Sample SteadyStateDetector::at(double t0) const {
  Sample s{t0, kNaN, {kNaN, kNaN, kNaN}};
  if (samples_.empty() || samples_.front().t > t0 + 1e-12) return s;
  for (size_t i = 0; i + 1 < samples_.size(); ++i) {
    const Sample& a = samples_[i];
    const Sample& b = samples_[i + 1];
    if (a.t <= t0 && t0 <= b.t) {
      const double w = b.t > a.t ? (t0 - a.t) / (b.t - a.t) : 0.0;
      s.area = a.area + w * (b.area - a.area);
      for (int k = 0; k < 3; ++k) s.D[k] = a.D[k] + w * (b.D[k] - a.D[k]);
      return s;
    }
  }
  return s;
}

double SteadyStateDetector::measure_at(size_t k) const {
  const Sample& now = samples_[k];
  const Sample before = at(now.t - window_);
  return std::abs(now.area - before.area) / (4 * M_PI);  // NaN propagates when before is unknown
}

bool SteadyStateDetector::steady() const {
  if (samples_.empty()) return false;
  const Sample& now = samples_.back();
  if (now.t < 2 * window_ - 1e-12) return false;
  // The measure below tol at every sample of the last window.
  for (size_t k = samples_.size(); k-- > 0 && samples_[k].t >= now.t - window_ - 1e-12;)
    if (!(measure_at(k) < tol_)) return false;
  const Sample before = at(now.t - window_);
  for (int k = 0; k < 3; ++k)
    if (!(std::abs(now.D[k] - before.D[k]) < kPlateau)) return false;
  return true;
}

Eigen::MatrixXd SteadyStateDetector::history() const {
  Eigen::MatrixXd h(static_cast<Eigen::Index>(samples_.size()), 5);
  for (size_t i = 0; i < samples_.size(); ++i) {
    const Sample& s = samples_[i];
    h.row(static_cast<Eigen::Index>(i)) << s.t, s.area, s.D[0], s.D[1], s.D[2];
  }
  return h;
}

void SteadyStateDetector::set_history(const Eigen::MatrixXd& h) {
  samples_.clear();
  // Checkpoints written before the plateau test hold (t, area) only: without D_ij the detector
  // starts afresh (one more window before the first verdict).
  if (h.cols() < 5) return;
  for (Eigen::Index i = 0; i < h.rows(); ++i) samples_.push_back({h(i, 0), h(i, 1), {h(i, 2), h(i, 3), h(i, 4)}});
}

}  // namespace capsflow
