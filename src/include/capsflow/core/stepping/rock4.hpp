#pragma once
// The fourth-order stabilised scheme of the ROCK4 family (docs/time-integration.md §5.8), with
// coefficients computed here (stepping/rock4_coefficients.hpp): the scheme "auto" picks where the
// wall is soft for its mesh, where accuracy sets the step and the fourth order pays. ρ, the
// controller, dense output and checkpoints are the shared StabilizedStepper's.
//
// Error estimate: y_{n+1} minus the embedded third-order solution, O(τ⁴): the controller's
// exponent 1/4. It grows like |z| on the stiff modes, which ROCK4 damps little, so the scene's
// stepper filters it (grid_scale_filter.hpp) before its norm.
//
// Stage predictor: the recurrence stages and u_1 as RKC2's (the same three-term shape); the four
// finishing stages, within a short step of u_1, from Y_0, Y_1, g_{s−5} and u_1.
#include "capsflow/core/stepping/rock4_coefficients.hpp"
#include "capsflow/core/stepping/stabilized_stepper.hpp"

namespace capsflow {

class Rock4 final : public StabilizedStepper {
 public:
  // The first error-controlled step spans at most 20 stages. ROCK4's tolerances are ~100× RKC2's
  // numbers, so the first guess (τ|F|/2 at the tolerance) can span up to 152 stages before any
  // estimate or rejection has checked ρ; on a Skalak wall at Ca_s = 1e-3 a stage's rotation solve
  // diverged inside such a step (§5.8). Shortening only what is that long leaves every other run as it was.
  static constexpr int kFirstStepStages = 20;

  explicit Rock4(Options opt);

 private:
  long stages(RightHandSide& f, double tau, int s) override;
  int stages_for(double tau_rho) const override { return Rock4Coefficients::stages_for(tau_rho); }
  double estimate_order() const override { return 4.0; }
  double first_step_interval() const override { return Rock4Coefficients::stability_interval(kFirstStepStages); }
  const char* name() const override { return "rock4"; }
  // The hint of finishing stage m (u_1 = g_base).
  EvaluationHint finishing_hint(int m, const Points& y, int base) const;

  Rock4Coefficients k_;  // of the last step; rebuilt only when the stage count changes
  Points kw_[4];         // F at the finishing stages
};

}  // namespace capsflow
