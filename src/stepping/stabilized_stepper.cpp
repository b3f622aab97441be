#include "capsflow/core/stepping/stabilized_stepper.hpp"

#include <algorithm>
#include <cmath>
#include <Eigen/Eigenvalues>
#include <limits>
#include <stdexcept>
#include <fmt/core.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

namespace capsflow {

namespace {
// Step-size controller: the classic safety factor 0.8 and growth bounds [0.1, 10] of RKC.
constexpr double kSafety = 0.8, kMinFactor = 0.1, kMaxFactor = 10.0;
// The first step: τ with the error of an Euler step, τ |F|/2, at the tolerance, but at most 0.1
// of γ̇t (a bounded guess; rejections correct it).
constexpr double kFirstStepMax = 0.1;
// Landing on a stop in equal steps: up to 20 % above the proposal (its safety factor 0.8 leaves a
// factor 2 in the error).
constexpr double kLandingStretch = 1.2;
// After an inner solve failed: a step a quarter as long (a nearer stage lets the warm start work).
constexpr double kFailureShrink = 0.25;
}  // namespace

void stage_weights(const Points& y, const Points* const* states, int m, double* w) {
  static_assert(StagePredictor::kTerms == 4, "three unknown weights at most");
  w[0] = 1;
  const int k = m - 1;  // unknowns: the weights of states 1..m−1 (states_0 takes the rest)
  if (k <= 0) return;
  // Normal equations of min |(y − s_0) − Σ c_a (s_a − s_0)|, padded to 3×3 with the identity.
  Eigen::Matrix3d G = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  const double* s0 = states[0]->data();
  const double* yy = y.data();
  const Eigen::Index n = y.size();
  double d[3];
  for (Eigen::Index e = 0; e < n; ++e) {
    const double t = yy[e] - s0[e];
    for (int a = 0; a < k; ++a) d[a] = states[a + 1]->data()[e] - s0[e];
    for (int a = 0; a < k; ++a) {
      b[a] += d[a] * t;
      for (int c = 0; c <= a; ++c) G(a, c) += d[a] * d[c];
    }
  }
  Eigen::Vector3d scale = Eigen::Vector3d::Zero();
  for (int a = 0; a < k; ++a) scale[a] = G(a, a) > 0 ? 1 / std::sqrt(G(a, a)) : 0.0;
  for (int a = 0; a < 3; ++a)
    for (int c = 0; c <= a; ++c) G(a, c) = G(c, a) = a < k ? G(a, c) * scale[a] * scale[c] : (a == c ? 1.0 : 0.0);
  b = b.cwiseProduct(scale);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(G);
  const double top = eig.eigenvalues().maxCoeff();  // ≥ 1: unit diagonal
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int a = 0; a < 3; ++a) {
    const double lambda = eig.eigenvalues()[a];
    if (lambda > 1e-12 * top) c += (eig.eigenvectors().col(a).dot(b) / lambda) * eig.eigenvectors().col(a);
  }
  c = c.cwiseProduct(scale);
  for (int a = 0; a < k; ++a) {
    w[a + 1] = c[a];
    w[0] -= c[a];
  }
}

void predict_stage(StagePredictor& p, const Points& y, const Points* const* states, const int* slots, int terms) {
  double w[StagePredictor::kTerms];
  stage_weights(y, states, terms, w);
  p.terms = terms;
  for (int t = 0; t < terms; ++t) p.slot[t] = slots[t], p.weight[t] = w[t];
}

EvaluationHint StabilizedStepper::stage_hint(int m, const Points& y, int keep_below) const {
  EvaluationHint h{EvaluationHint::Role::Trajectory, m};
  if (!opt_.predict_stages) return h;
  StagePredictor& p = h.predictor;
  // Slots: Y_0 in 0, Y_1 in 1, Y_m (m ≥ 2) in 2 + m mod 2. Y_0's solution is the last evaluation's
  // (F(y_n), or a probe δ-close to it), kept when Y_1 is evaluated; Y_s is not kept.
  if (m == 1) {
    p.keep_start = 0;
    p.keep = 1;
    return h;
  }
  const Points* states[StagePredictor::kTerms] = {&y0_, m >= 4 ? &y1_ : (m == 2 ? &yjm2_ : &yj_), &yjm2_, &yj_};
  const int slots[StagePredictor::kTerms] = {0, 1, 2 + (m - 1) % 2, 2 + m % 2};
  // distinct: {Y_0, Y_1}, {Y_0, Y_1, Y_2}, {Y_0, Y_1, Y_{m−1}, Y_{m−2}}
  predict_stage(p, y, states, slots, m == 2 ? 2 : (m == 3 ? 3 : 4));
  if (m < keep_below) p.keep = 2 + m % 2;
  return h;
}

double StabilizedStepper::rms(const Points& v) const {
  return v.rows() ? std::sqrt(v.squaredNorm() / static_cast<double>(v.rows())) : 0.0;
}

void StabilizedStepper::refresh_rho(RightHandSide& f, const Points& x) {
  // λ ≠ 1: after a rejected step the probes would be differenced against the discarded state's
  // second-kind solve, and σ came out 10–240× too large (docs/time-integration.md §5.8).
  if (probe_base_elsewhere_ && f.probes_difference_against_last_evaluation()) {
    f.evaluate(x, f0_, {EvaluationHint::Role::Trajectory, 0});
    ++rho_evaluations_;
    f0_valid_ = true;
  }
  probe_base_elsewhere_ = false;
  const SpectralRadiusEstimator::Result r = power_.estimate(f, x, f0_);
  rho_evaluations_ += r.evaluations;
  rho_ = opt_.rho_margin * r.sigma;
  analytic_at_refresh_ = opt_.analytic_rho ? opt_.analytic_rho(x) : 0.0;
  if (!r.converged) rho_ = std::max(rho_, analytic_at_refresh_);  // fall back on the analytic bound
  rho_refresh_ = rho_;
  steps_since_rho_ = 0;
  rho_stale_ = false;
}

StabilizedStepper::StabilizedStepper(Options opt, double beta_max) : opt_(std::move(opt)), beta_max_(beta_max) {}

double StabilizedStepper::proposed_step(RightHandSide& f, const Points& x) {
  if (tau_next_ > 0) return tau_next_;
  // First step: τ with the error of an Euler step, τ |F|/2, at the tolerance (then the controller
  // takes over); a bounded guess, rejections correct it.
  if (!f0_valid_) {
    f.evaluate(x, f0_, {EvaluationHint::Role::Trajectory, 0});
    f0_valid_ = true;
    probe_base_elsewhere_ = false;
  }
  const double v = rms(f0_);
  tau_next_ = v > 0 ? std::min(kFirstStepMax, std::sqrt(opt_.tolerance / v)) : kFirstStepMax;
  return tau_next_;
}

StabilizedStepper::StepReport StabilizedStepper::step(RightHandSide& f, Points& x, double tau) {
  StepReport rep;
  const long rho_before = rho_evaluations_;
  dense_valid_ = false;  // the stages below overwrite y_n and F_n
  if (!f0_valid_) {
    f.evaluate(x, f0_, {EvaluationHint::Role::Trajectory, 0});
    f0_valid_ = true;
    probe_base_elsewhere_ = false;
    ++rep.evaluations;
  }
  if (rho_stale_ || steps_since_rho_ >= opt_.rho_refresh_steps) {
    refresh_rho(f, x);
  } else if (opt_.analytic_rho && analytic_at_refresh_ > 0) {
    rho_ = rho_refresh_ * std::max(1.0, opt_.analytic_rho(x) / analytic_at_refresh_);
  }
  // Stage cap: a step that would need more stages is shortened to what the cap allows.
  if (tau * rho_ > beta_max_) tau = beta_max_ / rho_;
  // A first guess is capped where the scheme asks (Rock4::first_step_interval). Only a guess: a
  // fixed time.dt is the user's (and without error control tau_prev_ stays 0, so every step would
  // look like a first one).
  if (opt_.error_control && tau_prev_ == 0 && !last_rejected_) {
    const double first = first_step_interval();
    if (tau * rho_ > first) tau = first / rho_;
  }
  const int s = stages_for(tau * rho_);
  rep.tau = tau;
  rep.stages = s;
  y0_ = x;
  rep.evaluations += stages(f, tau, s);
  if (!yjm1_.allFinite() || !f1_.allFinite()) {
    rep.error = std::numeric_limits<double>::infinity();
  } else if (opt_.error_control) {
    if (opt_.filter_error) opt_.filter_error(est_);
    rep.error = rms(est_) / opt_.tolerance;
  }
  rep.accepted = !opt_.error_control ? std::isfinite(rep.error) : rep.error <= 1.0;
  at_state_ = rep.accepted;  // rejected: the last evaluation was at the discarded y_{n+1}
  probe_base_elsewhere_ = !rep.accepted;
  if (rep.accepted) {
    x = yjm1_;
    std::swap(f0_, f1_);
    dense_valid_ = true;
    dense_tau_ = tau;
    ++steps_since_rho_;
    control_after_accepted(tau, rep.error);
  } else {
    control_after_rejected(tau, rep.error);
  }
  rep.evaluations += rho_evaluations_ - rho_before;
  return rep;
}

void StabilizedStepper::control_after_accepted(double tau, double error) {
  if (opt_.error_control) {
    double fac = error > 0 ? kSafety * std::pow(error, -1.0 / estimate_order()) : kMaxFactor;
    // Predictive (PI) correction after an accepted step, as in RKC: do not grow faster than the
    // error history supports.
    if (tau_prev_ > 0 && err_prev_ > 0 && error > 0)
      fac = std::min(fac, fac * (tau / tau_prev_) * std::pow(err_prev_ / error, 1.0 / estimate_order()));
    if (last_rejected_) fac = std::min(fac, 1.0);
    tau_next_ = tau * std::clamp(fac, kMinFactor, kMaxFactor);
    tau_prev_ = tau;
    err_prev_ = error;
  } else {
    tau_next_ = tau;
  }
  last_rejected_ = false;
}

// The state is unchanged, and F_n with it. A rejection often means ρ moved: refresh it.
void StabilizedStepper::control_after_rejected(double tau, double error) {
  const double fac = std::isfinite(error) ? kSafety * std::pow(error, -1.0 / estimate_order()) : kMinFactor;
  tau_next_ = tau * std::clamp(fac, kMinFactor, 1.0);
  rho_stale_ = true;
  last_rejected_ = true;
}

bool StabilizedStepper::shorten_after_failure(double tau) {
  if (!opt_.error_control || !(tau > 0)) return false;
  // As after a rejection: the state is unchanged, and ρ may have moved with whatever defeated the solve.
  tau_next_ = kFailureShrink * tau;
  rho_stale_ = true;
  last_rejected_ = true;
  return true;
}

bool StabilizedStepper::set_tolerance(double tol) {
  if (!opt_.error_control) return false;
  if (!(tol > 0)) throw std::invalid_argument("StabilizedStepper::set_tolerance: the tolerance must be positive");
  // The error estimate grows like τ^q (q = 3 for RKC2, 4 for ROCK4): the step that meets the new
  // tolerance as the proposal met the old one is τ (new/old)^(1/q); the last error, in units of the
  // new tolerance, keeps the PI correction's ratio meaningful.
  const double ratio = tol / opt_.tolerance;
  tau_next_ *= std::pow(ratio, 1.0 / estimate_order());
  err_prev_ /= ratio;
  opt_.tolerance = tol;
  return true;
}

void StabilizedStepper::interpolate(double theta, Points& x) const {
  if (!dense_valid_) throw std::logic_error("StabilizedStepper::interpolate: no accepted step to interpolate in");
  // Cubic Hermite basis on [0, 1]: values at both ends and slopes τ F at both ends.
  const double t2 = theta * theta, t3 = t2 * theta;
  const double h00 = 2 * t3 - 3 * t2 + 1, h01 = 3 * t2 - 2 * t3;
  const double h10 = t3 - 2 * t2 + theta, h11 = t3 - t2;
  x.noalias() = h00 * y0_ + h01 * yjm1_ + (h10 * dense_tau_) * f1_ + (h11 * dense_tau_) * f0_;
}

double StabilizedStepper::next_step(RightHandSide& f, const Points& x, const StepRequest& r) {
  const double remaining = r.to_stop;
  // A fixed time.dt is the user's bound: it lands by shortening, as Heun's does, never stretched.
  if (!opt_.error_control) return std::min(opt_.fixed_dt, remaining);
  const double want = proposed_step(f, x);
  // Land on the next output time in equal steps rather than full steps and a sliver: a sliver
  // costs an evaluation per stage like any step and advances little. Up to 20 % above the
  // proposal (its safety factor 0.8 leaves a factor 2 in the error).
  return want >= remaining ? remaining : remaining / std::ceil(remaining / (kLandingStretch * want));
}

StepAttempt StabilizedStepper::attempt(RightHandSide& f, Points& x, double dt) {
  const StepReport r = step(f, x, dt);
  spdlog::trace("{}: tau {:.4e} s {} err {:.3f} {} evals {} rho {:.1f}", name(), r.tau, r.stages, r.error,
                r.accepted ? "accepted" : "rejected", r.evaluations, rho_);
  if (r.accepted) {
    stages_total_ += r.stages;
    stages_max_ = std::max<long>(stages_max_, r.stages);
    last_stages_ = r.stages;
  }
  return {r.accepted, r.tau, r.stages};
}

// Under "stabilized_step": a restart may switch between RKC2 and ROCK4 and keeps ρ and the
// controller; from a checkpoint of another scheme (Heun) the stepper starts afresh.
void StabilizedStepper::save(nlohmann::json& extra, Eigen::MatrixXd& matrix) const {
  extra["stabilized_step"] = scalar_state();
  matrix = matrix_state();
}

void StabilizedStepper::load(const nlohmann::json& extra, const Eigen::MatrixXd& matrix, const Points&) {
  if (!extra.contains("stabilized_step")) return;
  set_scalar_state(extra.at("stabilized_step"));
  set_matrix_state(matrix);
  at_state_ = false;  // F(y_n) is restored, but the wall's last evaluation is the checkpoint's
}

std::string StabilizedStepper::status() const {
  return fmt::format("{} s {:>3}", name(), last_stages_);
}

void StabilizedStepper::summarize(nlohmann::json& summary, const Points& x, long steps) const {
  summary["spectral_radius"] = rho_;
  // What the calibrated Heun constant implies at the final shape (real interval 2): the power
  // iteration is expected to see more on shapes the constant was not calibrated for.
  if (opt_.analytic_rho) summary["spectral_radius_analytic"] = opt_.analytic_rho(x);
  summary["stages_max"] = stages_max_;
  // Every counted step of an RKC run is an accepted one.
  summary["stages_mean"] = steps > 0 ? static_cast<double>(stages_total_) / static_cast<double>(steps) : 0.0;
  summary["spectral_radius_evaluations"] = rho_evaluations_;
}

nlohmann::json StabilizedStepper::scalar_state() const {
  return {{"rho", rho_}, {"rho_refresh", rho_refresh_}, {"analytic_at_refresh", analytic_at_refresh_},
          {"rho_evaluations", rho_evaluations_}, {"steps_since_rho", steps_since_rho_},
          {"rho_stale", rho_stale_}, {"f0_valid", f0_valid_}, {"tau_next", tau_next_},
          {"tau_prev", tau_prev_}, {"err_prev", err_prev_}, {"last_rejected", last_rejected_},
          {"stages_total", stages_total_}, {"stages_max", stages_max_}};
}

void StabilizedStepper::set_scalar_state(const nlohmann::json& j) {
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
  stages_total_ = j.at("stages_total");
  stages_max_ = j.at("stages_max");
}

Eigen::MatrixXd StabilizedStepper::matrix_state() const {
  const Points& d = power_.direction();
  const Eigen::Index n = std::max(f0_.rows(), d.rows());
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n, 6);
  if (f0_valid_ && f0_.rows() == n) m.leftCols(3) = f0_;
  if (d.rows() == n) m.rightCols(3) = d;
  return m;
}

void StabilizedStepper::set_matrix_state(const Eigen::MatrixXd& m) {
  if (m.cols() != 6) {
    f0_valid_ = false;
    return;
  }
  f0_ = m.leftCols(3);
  power_.set_direction(m.rightCols(3));
}

}  // namespace capsflow
