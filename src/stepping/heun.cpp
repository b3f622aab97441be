#include "capsflow/core/stepping/heun.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

namespace capsflow {

void Heun::step(RightHandSide& f, Points& x, double dt) {
  f.evaluate(x, v1_, {EvaluationHint::Role::Trajectory, 0});
  xs_.noalias() = x + dt * v1_;
  f.evaluate(xs_, v2_, {EvaluationHint::Role::Trajectory, 1});
  x += (0.5 * dt) * (v1_ + v2_);
}

void Heun::refresh_rho(RightHandSide& f, const Points& x, long step) {
  f.evaluate(x, f_, {});
  const SpectralRadiusEstimator::Result r = power_.estimate(f, x, f_);
  rho_ = r.converged ? kSpectralRadiusMargin * r.sigma : 0.0;  // unconverged: the calibrated limit alone
  rho_step_ = step;
}

double Heun::next_step(RightHandSide& f, const Points& x, const StepRequest& r) {
  double dt = opt_.dt;
  if (opt_.dt_auto) {
    if (r.step % kRhoEvery == 0 && rho_step_ != r.step) refresh_rho(f, x, r.step);
    const double limit = opt_.stable_step(x);
    // Heun's real stability interval is [−2, 0]: Δt ≤ 2/ρ.
    dt = opt_.safety * (rho_ > 0 ? std::min(limit, 2.0 / rho_) : limit);
  }
  return std::min(dt, r.to_stop);  // land on the output time
}

StepAttempt Heun::attempt(RightHandSide& f, Points& x, double dt) {
  step(f, x, dt);
  return {true, dt, evaluations_per_step};
}

void Heun::save(nlohmann::json& extra, Eigen::MatrixXd& matrix) const {
  extra["heun_rho"] = {{"rho", rho_}, {"step", rho_step_}};
  if (power_.direction().rows() > 0) matrix = power_.direction();
}

void Heun::load(const nlohmann::json& extra, const Eigen::MatrixXd& matrix, const Points& x) {
  if (!extra.contains("heun_rho")) return;  // older checkpoints: measured again at the next multiple of kRhoEvery
  rho_ = extra.at("heun_rho").at("rho");
  rho_step_ = extra.at("heun_rho").at("step");
  if (matrix.rows() == x.rows() && matrix.cols() == 3) power_.set_direction(matrix);
}

void Heun::summarize(nlohmann::json& summary, const Points&, long) const {
  if (rho_ > 0) summary["spectral_radius"] = rho_;
}

}  // namespace capsflow
