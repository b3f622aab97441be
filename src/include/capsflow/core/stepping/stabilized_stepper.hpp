#pragma once
// What the two stabilised explicit schemes share (docs/time-integration.md §5.6): the spectral
// radius, the stage count it implies, the error-controlled step, dense output, the stage predictor
// and the checkpointed state. The schemes themselves — their stages and error estimates — are
// Rkc2 (stepping/rkc2.hpp) and Rock4 (stepping/rock4.hpp).
//
// A step of size τ from y_n with F_n = F(y_n) (kept from the previous step: first same as last):
//   1. ρ: the spectral radius (SpectralRadiusEstimator, × margin), refreshed every
//      `rho_refresh_steps` accepted steps and after a rejection;
//   2. s: the fewest stages whose stability interval β(s) covers τ ρ (the scheme's stages_for);
//   3. the scheme's s stages, the optional projection of y_{n+1} onto an invariant (the capsule's
//      volume, rhs/volume_constraint.hpp), then F_{n+1} = F(y_{n+1});
//   4. error: the scheme's estimate (optionally filtered), as the RMS over nodes in units of ℓ,
//      against `tolerance`; accepted when err = RMS/tolerance ≤ 1; the next τ from err^(−1/q),
//      q the estimate's order + 1, with RKC's predictive (PI) correction.
// With error_control = false every step is accepted at the given τ (stages still from ρ).
//
// As a TimeStepper: the step is the controller's proposal, the last stretch before a stop cut into
// equal steps of at most 1.2× the proposal rather than full steps and a sliver; or, without error
// control, the fixed `fixed_dt`, shortened only where it would pass an output time. With error
// control it has dense output, so its stops are checkpoints and t_end, not output times: the cubic
// Hermite interpolant of y_n, F_n, y_{n+1}, F_{n+1} (all at hand after a step), whose error
// O(τ⁴) lies below RKC2's local error O(τ³) (Sommeijer, Shampine & Verwer 1998 give RKC the same
// interpolant).
#include <functional>
#include <limits>
#include <utility>
#include <nlohmann/json_fwd.hpp>

#include "capsflow/core/stepping/spectral_radius.hpp"
#include "capsflow/core/stepping/time_stepper.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

// The weights w (Σ w = 1) of the combination of states[0..m) closest to y, min |y − Σ w_k
// states_k| (Frobenius), m ≤ StagePredictor::kTerms. Directions in which the differences
// states_k − states_0 are nearly dependent (relative singular value below 1e-6, after scaling
// each to unit length) are dropped rather than extrapolated along; a state equal to states_0 gets
// weight 0. Deterministic: serial sums in a fixed order.
void stage_weights(const Points& y, const Points* const* states, int m, double* w);
// The predictor of a stage y: its stage_weights on the given states, whose solutions the
// right-hand side holds in those slots.
void predict_stage(StagePredictor& p, const Points& y, const Points* const* states, const int* slots, int terms);

class StabilizedStepper : public TimeStepper {
 public:
  // ρ refreshed every 10 accepted steps: RKC refreshes every 25, but the steps here are long.
  static constexpr int kRhoRefreshSteps = 10;
  // The stage cap: round-off in the Chebyshev recurrence grows like s²·ε.
  static constexpr int kMaxStages = 250;
  struct Options {
    double tolerance = 1e-4;      // local error per step, RMS over nodes, in units of ℓ
    bool error_control = true;
    double fixed_dt = 0;          // the step without error control (next_step)
    double rho_margin = kSpectralRadiusMargin;  // ρ = margin × power-iteration estimate
    int rho_refresh_steps = kRhoRefreshSteps;
    int max_stages = kMaxStages;
    // The analytic bound at a state (stepping/stability.hpp, from the current shortest edge; may be
    // empty). It is the fallback when the power iteration does not converge, and between refreshes
    // ρ follows its growth: ρ(x) = ρ_refresh × max(1, bound(x)/bound(x_refresh)), so a mesh that
    // shrinks is not stepped with a stale ρ.
    std::function<double(const Points&)> analytic_rho;
    std::function<void(Points&)> project;  // applied to y_{n+1} before F(y_{n+1}); may be empty
    // The stage predictor (EvaluationHint::predictor): each stage Y_m, m ≥ 2, is told the weights
    // of the combination of Y_0, Y_1, Y_{m−2}, Y_{m−1} closest to it (stage_weights), so that the
    // right-hand side starts its inner solve from the same combination of their solutions.
    bool predict_stages = true;
    // Applied to the error estimate before its norm (may be empty). ROCK4 gets the grid-scale
    // low-pass (stepping/grid_scale_filter.hpp): its estimate grows like |z| on the stiff modes.
    std::function<void(Points&)> filter_error;
  };
  struct StepReport {
    bool accepted = false;
    double tau = 0;        // the step attempted (may be less than asked: stage cap)
    double error = 0;      // err (≤ 1 accepted); 0 without error control
    int stages = 0;
    long evaluations = 0;  // right-hand-side evaluations of this attempt, ρ estimate included
  };

  // One attempt of size tau from x. Accepted: x ← y_{n+1}. Rejected: x unchanged.
  StepReport step(RightHandSide& f, Points& x, double tau);
  // The controller's proposal for the next step (before clipping to output times).
  double proposed_step(RightHandSide& f, const Points& x);

  double spectral_radius() const { return rho_; }  // margin included; 0 before the first estimate
  long rho_evaluations() const { return rho_evaluations_; }
  // F at the current state (valid after a step or a restart); the right-hand side was last
  // evaluated there, so loads, forces and energies it holds belong to the current state.
  const Points& velocity() const { return f0_; }
  bool has_velocity() const { return f0_valid_; }
  void forget_velocity() { f0_valid_ = false, dense_valid_ = false; }
  const Options& options() const { return opt_; }

  // TimeStepper
  double next_step(RightHandSide& f, const Points& x, const StepRequest& r) override;
  StepAttempt attempt(RightHandSide& f, Points& x, double dt) override;
  bool interpolates() const override { return opt_.error_control; }
  void interpolate(double theta, Points& x) const override;
  bool shorten_after_failure(double dt) override;
  bool set_tolerance(double tol) override;
  const Points* velocity_at_state() const override { return at_state_ && f0_valid_ ? &f0_ : nullptr; }
  void forget_state() override { forget_velocity(); }
  void save(nlohmann::json& extra, Eigen::MatrixXd& matrix) const override;
  void load(const nlohmann::json& extra, const Eigen::MatrixXd& matrix, const Points& x) override;
  std::string status() const override;
  void summarize(nlohmann::json& summary, const Points& x, long steps) const override;

  // Everything a restart needs to continue bit for bit: scalars as JSON, F_n and the power
  // iteration's direction as matrices.
  nlohmann::json scalar_state() const;
  void set_scalar_state(const nlohmann::json& j);
  Eigen::MatrixXd matrix_state() const;  // [F_n | direction] (N × 6), empty before the first step
  void set_matrix_state(const Eigen::MatrixXd& m);

 protected:
  // beta_max: the stability interval at the stage cap (the longest step it allows is β_max/ρ).
  StabilizedStepper(Options opt, double beta_max);

  // The scheme: the stages of one step of size tau from y0_ (F = f0_), leaving y_{n+1} in yjm1_,
  // F(y_{n+1}) in f1_ and, with error control, the error estimate in est_; returns the evaluations.
  virtual long stages(RightHandSide& f, double tau, int s) = 0;
  virtual int stages_for(double tau_rho) const = 0;  // the fewest stages with β(s) ≥ τρ
  virtual double estimate_order() const = 0;         // the estimate's order + 1: the controller's 1/exponent
  // The longest τρ of a first error-controlled step, before any estimate or rejection has checked ρ.
  virtual double first_step_interval() const { return std::numeric_limits<double>::infinity(); }
  virtual const char* name() const = 0;  // "rkc", "rock4": the status line's

  // The hint of the evaluation at stage point Y_m (m ≥ 1; yjm2_ = Y_{m−1}, yj_ = Y_{m−2}); stages
  // m < keep_below keep their solution for the stages after them.
  EvaluationHint stage_hint(int m, const Points& y, int keep_below) const;

  Options opt_;
  // The stage vectors: y0_ = y_n, y1_ = Y_1 (the stage predictor), yjm1_/yjm2_/yj_ the recurrence's
  // last three, fj_ a stage's F, f0_ = F_n, f1_ = F_{n+1}, est_ the error estimate.
  Points f0_, f1_, y0_, y1_, yjm1_, yjm2_, yj_, fj_, est_;

 private:
  void refresh_rho(RightHandSide& f, const Points& x);
  double rms(const Points& v) const;
  void control_after_accepted(double tau, double error);
  void control_after_rejected(double tau, double error);

  double beta_max_;
  SpectralRadiusEstimator power_;
  double rho_ = 0, rho_refresh_ = 0, analytic_at_refresh_ = 0;
  long rho_evaluations_ = 0;
  int steps_since_rho_ = 0;
  bool rho_stale_ = true;
  bool f0_valid_ = false;
  double tau_next_ = 0, tau_prev_ = 0, err_prev_ = 0;
  bool last_rejected_ = false;
  bool at_state_ = false;  // the last evaluation was F(y_{n+1}) of an accepted step: the current state
  // The right-hand side's last trajectory evaluation was not at the current state (a rejected
  // step's was at its discarded y_{n+1}): a ρ refresh evaluates F there first where the right-hand
  // side's probes difference against it (refresh_rho).
  bool probe_base_elsewhere_ = false;
  // Dense output of the last accepted step: y_n = y0_, F_n = f1_, y_{n+1} = yjm1_, F_{n+1} = f0_.
  bool dense_valid_ = false;
  double dense_tau_ = 0;
  long stages_total_ = 0, stages_max_ = 0;  // over accepted steps (all segments)
  int last_stages_ = 0;
};

}  // namespace capsflow
