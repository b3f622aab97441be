#include "capsflow/core/health/steady_state.hpp"

#include <cmath>
#include <limits>

namespace capsflow {

ShapeTensor shape_tensor(const InertiaEllipsoid& e) {
  const double mean = e.semi_axes.sum() / 3;
  const Mat3 A = e.axes * e.semi_axes.asDiagonal() * e.axes.transpose() / mean;
  return {A(0, 0), A(0, 1), A(0, 2), A(1, 1), A(1, 2), A(2, 2)};
}

void SteadyStateDetector::add(double t, double area, const std::array<double, 3>& D, const ShapeTensor& A) {
  samples_.push_back({t, area, D, A});
  // Keep two windows (and one sample before) so the measure can be checked over the last window.
  while (samples_.size() > 2 && samples_[1].t <= t - 2 * window_) samples_.pop_front();
}

void SteadyStateDetector::add(double t, double area, const InertiaEllipsoid& e) {
  const TaylorDeformation d = taylor_deformation(e);
  add(t, area, {d.D12, d.D13, d.D23}, shape_tensor(e));
}

SteadyStateDetector::Sample SteadyStateDetector::at(double t0) const {
  Sample s{t0, kNaN, {kNaN, kNaN, kNaN}, {kNaN, kNaN, kNaN, kNaN, kNaN, kNaN}};
  if (samples_.empty() || samples_.front().t > t0 + 1e-12) return s;
  for (size_t i = 0; i + 1 < samples_.size(); ++i) {
    const Sample& a = samples_[i];
    const Sample& b = samples_[i + 1];
    if (a.t <= t0 && t0 <= b.t) {
      const double w = b.t > a.t ? (t0 - a.t) / (b.t - a.t) : 0.0;
      s.area = a.area + w * (b.area - a.area);
      for (int k = 0; k < 3; ++k) s.D[k] = a.D[k] + w * (b.D[k] - a.D[k]);
      for (int k = 0; k < 6; ++k) s.A[k] = a.A[k] + w * (b.A[k] - a.A[k]);
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
  // The shape tensor, orientation included, at two lags (NaN, before the samples, fails).
  for (const double lag : {window_, window_ / 2}) {
    const Sample then = at(now.t - lag);
    for (int k = 0; k < 6; ++k)
      if (!(std::abs(now.A[k] - then.A[k]) < kTensorPlateau)) return false;
  }
  return true;
}

Eigen::MatrixXd SteadyStateDetector::history() const {
  Eigen::MatrixXd h(static_cast<Eigen::Index>(samples_.size()), 11);
  for (size_t i = 0; i < samples_.size(); ++i) {
    const Sample& s = samples_[i];
    h.row(static_cast<Eigen::Index>(i)) << s.t, s.area, s.D[0], s.D[1], s.D[2], s.A[0], s.A[1], s.A[2], s.A[3],
        s.A[4], s.A[5];
  }
  return h;
}

void SteadyStateDetector::set_history(const Eigen::MatrixXd& h) {
  samples_.clear();
  // Checkpoints written before the plateau tests hold (t, area) or (t, area, D_ij) only: without
  // the shape tensor the detector starts afresh (one more window before the first verdict).
  if (h.cols() < 11) return;
  for (Eigen::Index i = 0; i < h.rows(); ++i)
    samples_.push_back({h(i, 0), h(i, 1), {h(i, 2), h(i, 3), h(i, 4)}, {h(i, 5), h(i, 6), h(i, 7), h(i, 8), h(i, 9), h(i, 10)}});
}

}  // namespace capsflow
