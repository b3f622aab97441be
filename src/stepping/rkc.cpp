#include "capsflow/core/stepping/rkc.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

namespace capsflow {

namespace {
// Step-size controller: the classic safety factor 0.8 and growth bounds [0.1, 10] of RKC.
constexpr double kSafety = 0.8, kMinFactor = 0.1, kMaxFactor = 10.0;
}  // namespace

double Rkc::rms(const Points& v) const {
  return v.rows() ? std::sqrt(v.squaredNorm() / static_cast<double>(v.rows())) : 0.0;
}

void Rkc::refresh_rho(const Rhs& f, const Points& x) {
  const SpectralRadiusEstimator::Result r = power_.estimate(f, x, f0_);
  rho_evaluations_ += r.evaluations;
  rho_ = opt_.rho_margin * r.sigma;
  analytic_at_refresh_ = opt_.analytic_rho ? opt_.analytic_rho(x) : 0.0;
  if (!r.converged) rho_ = std::max(rho_, analytic_at_refresh_);  // fall back on the analytic bound
  rho_refresh_ = rho_;
  steps_since_rho_ = 0;
  rho_stale_ = false;
}

double Rkc::proposed_step(const Rhs& f, const Points& x) {
  if (tau_next_ > 0) return tau_next_;
  // First step: τ with the error of an Euler step, τ |F|/2, at the tolerance (then the controller
  // takes over); a bounded guess, rejections correct it.
  if (!f0_valid_) {
    f(x, f0_);
    f0_valid_ = true;
  }
  const double v = rms(f0_);
  tau_next_ = v > 0 ? std::min(0.1, std::sqrt(opt_.tolerance / v)) : 0.1;
  return tau_next_;
}

Rkc::StepReport Rkc::step(const Rhs& f, Points& x, double tau) {
  StepReport rep;
  const long rho_before = rho_evaluations_;
  if (!f0_valid_) {
    f(x, f0_);
    f0_valid_ = true;
    ++rep.evaluations;
  }
  if (rho_stale_ || steps_since_rho_ >= opt_.rho_refresh_steps) {
    refresh_rho(f, x);
  } else if (opt_.analytic_rho && analytic_at_refresh_ > 0) {
    rho_ = rho_refresh_ * std::max(1.0, opt_.analytic_rho(x) / analytic_at_refresh_);
  }
  // Stage cap: a step that would need more stages is shortened to what the cap allows.
  if (tau * rho_ > beta_max_) tau = beta_max_ / rho_;
  const int s = RkcCoefficients::stages_for(tau * rho_, opt_.damping);
  if (k_.stages != s) k_ = RkcCoefficients::make(s, opt_.damping);
  const RkcCoefficients& k = k_;
  rep.tau = tau;
  rep.stages = s;

  y0_ = x;
  // Y_1 = Y_0 + μ̃_1 τ F(Y_0)
  yjm2_ = y0_;
  yjm1_.noalias() = y0_ + (k.mu_t[1] * tau) * f0_;
  for (int j = 2; j <= s; ++j) {
    f(yjm1_, fj_);
    ++rep.evaluations;
    yj_.noalias() = (1 - k.mu[j] - k.nu[j]) * y0_ + k.mu[j] * yjm1_ + k.nu[j] * yjm2_ +
                    (k.mu_t[j] * tau) * fj_ + (k.gamma_t[j] * tau) * f0_;
    std::swap(yjm2_, yjm1_);
    std::swap(yjm1_, yj_);
  }
  // yjm1_ = Y_s = y_{n+1}; its velocity is the next step's F_n.
  if (opt_.project && yjm1_.allFinite()) opt_.project(yjm1_);
  f(yjm1_, f1_);
  ++rep.evaluations;
  if (!yjm1_.allFinite() || !f1_.allFinite()) {
    rep.error = std::numeric_limits<double>::infinity();
  } else if (opt_.error_control) {
    est_.noalias() = (12.0 / 15.0) * (y0_ - yjm1_) + (6.0 * tau / 15.0) * (f0_ + f1_);
    rep.error = rms(est_) / opt_.tolerance;
  }
  rep.accepted = !opt_.error_control ? std::isfinite(rep.error) : rep.error <= 1.0;
  if (rep.accepted) {
    x = yjm1_;
    std::swap(f0_, f1_);
    ++steps_since_rho_;
    if (opt_.error_control) {
      double fac = rep.error > 0 ? kSafety * std::pow(rep.error, -1.0 / 3.0) : kMaxFactor;
      // Predictive (PI) correction after an accepted step, as in RKC: do not grow faster than the
      // error history supports.
      if (tau_prev_ > 0 && err_prev_ > 0 && rep.error > 0)
        fac = std::min(fac, fac * (tau / tau_prev_) * std::pow(err_prev_ / rep.error, 1.0 / 3.0));
      if (last_rejected_) fac = std::min(fac, 1.0);
      tau_next_ = tau * std::clamp(fac, kMinFactor, kMaxFactor);
      tau_prev_ = tau;
      err_prev_ = rep.error;
    } else {
      tau_next_ = tau;
    }
    last_rejected_ = false;
  } else {
    // The state is unchanged, and F_n with it. A rejection often means ρ moved: refresh it.
    const double fac = std::isfinite(rep.error) ? kSafety * std::pow(rep.error, -1.0 / 3.0) : kMinFactor;
    tau_next_ = tau * std::clamp(fac, kMinFactor, 1.0);
    rho_stale_ = true;
    last_rejected_ = true;
  }
  rep.evaluations += rho_evaluations_ - rho_before;
  return rep;
}

nlohmann::json Rkc::scalar_state() const {
  return {{"rho", rho_}, {"rho_refresh", rho_refresh_}, {"analytic_at_refresh", analytic_at_refresh_},
          {"rho_evaluations", rho_evaluations_}, {"steps_since_rho", steps_since_rho_},
          {"rho_stale", rho_stale_}, {"f0_valid", f0_valid_}, {"tau_next", tau_next_},
          {"tau_prev", tau_prev_}, {"err_prev", err_prev_}, {"last_rejected", last_rejected_}};
}

void Rkc::set_scalar_state(const nlohmann::json& j) {
  rho_ = j.at("rho");
  rho_refresh_ = j.at("rho_refresh");
  analytic_at_refresh_ = j.at("analytic_at_refresh");
  rho_evaluations_ = j.at("rho_evaluations");
  steps_since_rho_ = j.at("steps_since_rho");
  rho_stale_ = j.at("rho_stale");
  f0_valid_ = j.at("f0_valid");
  tau_next_ = j.at("tau_next");
  tau_prev_ = j.at("tau_prev");
  err_prev_ = j.at("err_prev");
  last_rejected_ = j.at("last_rejected");
}

Eigen::MatrixXd Rkc::matrix_state() const {
  const Points& d = power_.direction();
  const Eigen::Index n = std::max(f0_.rows(), d.rows());
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n, 6);
  if (f0_valid_ && f0_.rows() == n) m.leftCols(3) = f0_;
  if (d.rows() == n) m.rightCols(3) = d;
  return m;
}

void Rkc::set_matrix_state(const Eigen::MatrixXd& m) {
  if (m.cols() != 6) {
    f0_valid_ = false;
    return;
  }
  f0_ = m.leftCols(3);
  power_.set_direction(m.rightCols(3));
}

}  // namespace capsflow
