#pragma once
// Explicit second-order Runge–Kutta (Heun), the paper's scheme (docs/time-integration.md §5.5):
//   v1 = f(x),  x* = x + Δt v1,  v2 = f(x*),  x ← x + Δt (v1 + v2)/2.
// Two right-hand-side evaluations per step; stable for Δt below the limit of stepping/stability.hpp.
//
// Step control: a fixed time.dt, or (dt = "auto") dt_safety × the stable step, where the stable
// step is the calibrated limit at the current shortest edge and, when measured, 2/ρ: the
// calibrated constant covers a/b ≤ 1.4 and misses the stiffness of elongated shapes (a/b = 4: the
// power iteration sees 1.35× the constant's bound at t = 0). ρ is measured every kRhoEvery steps.
#include <functional>

#include "capsflow/core/stepping/spectral_radius.hpp"
#include "capsflow/core/stepping/time_stepper.hpp"

namespace capsflow {

class Heun final : public TimeStepper {
 public:
  struct Options {
    bool dt_auto = false;
    double dt = 0;       // the fixed step (dt_auto = false)
    double safety = 1;   // time.dt_safety: the automatic step is safety × the stable step
    std::function<double(const Points&)> stable_step;  // the calibrated limit at a state (dt_auto)
  };
  static constexpr long kRhoEvery = 50;
  static constexpr int evaluations_per_step = 2;

  Heun() = default;
  explicit Heun(Options opt) : opt_(std::move(opt)) {}

  // One step of size dt from x (in place): the formula above, no step control.
  void step(RightHandSide& f, Points& x, double dt);

  double next_step(RightHandSide& f, const Points& x, const StepRequest& r) override;
  StepAttempt attempt(RightHandSide& f, Points& x, double dt) override;
  const Points* velocity_at_state() const override { return nullptr; }  // the last evaluation is at the predictor
  void forget_state() override {}
  void save(nlohmann::json& extra, Eigen::MatrixXd& matrix) const override;
  void load(const nlohmann::json& extra, const Eigen::MatrixXd& matrix, const Points& x) override;
  std::string status() const override { return "heun"; }
  void summarize(nlohmann::json& summary, const Points& x, long steps) const override;

 private:
  void refresh_rho(RightHandSide& f, const Points& x, long step);

  Options opt_;
  SpectralRadiusEstimator power_;
  double rho_ = 0;      // margin included; 0: not measured (the calibrated limit alone)
  long rho_step_ = -1;  // the step at which rho_ was measured
  Points v1_, v2_, xs_, f_;  // scratch, reused across steps
};

}  // namespace capsflow
