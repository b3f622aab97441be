#include "capsflow/core/dynamics/steady_state.hpp"

#include <cmath>
#include <limits>

namespace capsflow {

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

}  // namespace capsflow
