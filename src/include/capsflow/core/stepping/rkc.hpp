#pragma once
// Damped second-order Runge–Kutta–Chebyshev (RKC2) with local error control: the default time
// integrator (docs/time-integration.md §5.7) — and, with Method::Rock4, the fourth-order ROCK4
// family (stepping/rock4_coefficients.hpp, §5.9), whose steps share everything below but the stages,
// the error estimate (embedded third order, O(τ⁴): the controller's exponent 1/4) and the stage
// count (ℓ_s ≈ 0.353 s²). The numbered outline below is RKC2's. Why RKC2 and not ROCK2: both have stability
// intervals growing like s² (0.65 s² and 0.81 s²); RKC2's coefficients are closed-form (no stored
// tables), it has a free embedded error estimate, and the capsule Jacobian's spectrum is real up to
// the O(γ̇) flow terms, where ROCK2's better damping of imaginary parts buys nothing.
//
// A step of size τ from y_n with F_n = F(y_n) (kept from the previous step: first same as last):
//   1. ρ: the spectral radius (SpectralRadiusEstimator, × margin), refreshed every
//      `rho_refresh_steps` accepted steps and after a rejection;
//   2. s: the fewest stages with β(s) ≥ τ ρ (RkcCoefficients::stages_for);
//   3. the s stages, the optional projection of y_{n+1} onto an invariant (the capsule's volume,
//      rhs/volume_constraint.hpp), then F_{n+1} = F(y_{n+1});
//   4. error: Est = [12 (y_n − y_{n+1}) + 6 τ (F_n + F_{n+1})] / 15 (Sommeijer et al. 1998), measured
//      as the RMS over nodes of |Est_i| in units of ℓ, against `tolerance`; the step is accepted
//      when err = RMS/tolerance ≤ 1, and the next τ follows from err^(−1/3) (local error O(τ³)).
// With error_control = false every step is accepted at the given τ (stages still from ρ).
//
// As a TimeStepper: the step is the controller's proposal, the last stretch before a stop cut into
// equal steps of at most 1.2× the proposal rather than full steps and a sliver; or, without error
// control, the fixed `fixed_dt`, shortened only where it would pass an output time. With error
// control it has dense output, so its stops are checkpoints and t_end, not output times: the cubic
// Hermite interpolant of y_n, F_n, y_{n+1}, F_{n+1} (all at hand after a step), whose error
// O(τ⁴) lies below the step's local error O(τ³) (Sommeijer, Shampine & Verwer 1998 give RKC the
// same interpolant).
#include <functional>
#include <utility>
#include <nlohmann/json_fwd.hpp>

#include "capsflow/core/stepping/rkc_coefficients.hpp"
#include "capsflow/core/stepping/rock4_coefficients.hpp"
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

class Rkc final : public TimeStepper {
 public:
  // The stage scheme: damped RKC2 (second order, β ≈ 0.65 s²) or the fourth-order ROCK4 family
  // (β ≈ 0.35 s², Rock4Coefficients). Everything else — ρ, the controller, dense output,
  // checkpoints — is shared; the controller's exponent follows the estimate's order.
  enum class Method { Rkc2, Rock4 };
  struct Options {
    Method method = Method::Rkc2;
    double tolerance = 1e-4;      // local error per step, RMS over nodes, in units of ℓ
    bool error_control = true;
    double fixed_dt = 0;          // the step without error control (next_step)
    double rho_margin = kSpectralRadiusMargin;  // ρ = margin × power-iteration estimate
    int rho_refresh_steps = 10;   // RKC refreshes every 25 steps; ours are long (see docs)
    int max_stages = 250;         // round-off in the Chebyshev recurrence grows like s²·ε
    double damping = RkcCoefficients::kDefaultDamping;
    // The analytic bound at a state (stepping/stability.hpp, from the current shortest edge; may be
    // empty). It is the fallback when the power iteration does not converge, and between refreshes
    // ρ follows its growth: ρ(x) = ρ_refresh × max(1, bound(x)/bound(x_refresh)), so a mesh that
    // shrinks is not stepped with a stale ρ.
    std::function<double(const Points&)> analytic_rho;
    std::function<void(Points&)> project;  // applied to y_{n+1} before F(y_{n+1}); may be empty
    // The stage predictor (EvaluationHint::predictor): each stage Y_m, m ≥ 2, is told the weights
    // of the combination of Y_0, Y_1, Y_{m−2}, Y_{m−1} closest to it (stage_weights), so that the
    // right-hand side starts its inner solve from the same combination of their solutions. ROCK4:
    // its recurrence stages and u_1 the same way, its finishing stages from Y_0, Y_1, g_{s−5}, u_1.
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

  explicit Rkc(Options opt);

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

 private:
  void refresh_rho(RightHandSide& f, const Points& x);
  // The stages of one step of size tau from y0_ (F = f0_): y_{n+1} in yjm1_, F(y_{n+1}) in f1_, the
  // error estimate in est_ (with error control); returns the evaluations.
  long rkc2_stages(RightHandSide& f, double tau, int s);
  long rock4_stages(RightHandSide& f, double tau, int s);
  // The error estimate's order + 1: the controller's exponent is its inverse.
  double estimate_order() const { return opt_.method == Method::Rock4 ? 4.0 : 3.0; }
  // The hint of the evaluation at stage point Y_m (m ≥ 1; yjm2_ = Y_{m−1}, yj_ = Y_{m−2}).
  EvaluationHint stage_hint(int m, const Points& y, int keep_below) const;  // stages m < keep_below keep their solution
  EvaluationHint finishing_hint(int m, const Points& y, int base) const;    // ROCK4's stages after u_1 = g_base
  double rms(const Points& v) const;

  Options opt_;
  double beta_max_;      // β(max_stages): the longest step the stage cap allows is β_max/ρ
  RkcCoefficients k_;    // of the last step; rebuilt only when the stage count changes
  Rock4Coefficients k4_;  // the same for ROCK4
  Points kw_[4];          // ROCK4: F at the finishing stages
  SpectralRadiusEstimator power_;
  double rho_ = 0, rho_refresh_ = 0, analytic_at_refresh_ = 0;
  long rho_evaluations_ = 0;
  int steps_since_rho_ = 0;
  bool rho_stale_ = true;
  Points f0_, f1_, y0_, y1_, yjm1_, yjm2_, yj_, fj_, est_;  // y1_ = Y_1 (the stage predictor)
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
