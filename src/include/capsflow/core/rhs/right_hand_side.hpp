#pragma once
// The seam between a time scheme and the physics: F(x) = dx/dt at positions x (N×3). The schemes
// of stepping/ call nothing else; the capsule problem implements it (rhs/capsule_dynamics.hpp).
//
// An implementation may keep inner-solver warm starts from one call to the next (the GSMB rotation
// solve does). The hint tells it where the point lies in the scheme, so that it can predict its
// inner solve from earlier stages (StagePredictor), or keep a spectral-radius probe from moving
// its warm start. Results do not depend on the hint beyond the inner solvers' tolerances.
#include <array>
#include <functional>
#include <stdexcept>
#include <utility>

#include "capsflow/core/types.hpp"

namespace capsflow {

// The stage predictor (docs/time-integration.md §5.6): a scheme whose stage states are linear
// combinations of earlier ones tells the right-hand side which, and the right-hand side starts its
// inner solve from the same combination of their solutions. The right-hand side keeps solutions in
// kSlots slots: keep_start keeps the solution of the last evaluation (made before this one), keep
// this evaluation's; this state ≈ Σ weight_k × (the state whose solution is in slot_k), Σ weight = 1.
// terms = 0: no prediction (start from the last evaluation's solution, the default).
struct StagePredictor {
  static constexpr int kSlots = 4, kTerms = 4;
  int keep_start = -1, keep = -1;
  int terms = 0;
  std::array<int, kTerms> slot{};
  std::array<double, kTerms> weight{};
};

struct EvaluationHint {
  enum class Role {
    Trajectory,  // a state or stage of a step: the solution passes near it
    Probe,       // y + δw of the spectral-radius power iteration: off the trajectory
    Output,      // the current state, for the run's output (loads, energies, velocities)
  };
  EvaluationHint() = default;
  EvaluationHint(Role r, int j) : role(r), stage(j) {}
  Role role = Role::Trajectory;
  int stage = 0;  // 0: at the step's start state y_n; j ≥ 1: the scheme's j-th stage point
  StagePredictor predictor;
};

// An inner solve of the right-hand side failed (one line: what, and how far it got). The run
// keeps its last healthy state and stops as "solver_failure" (driver/stop_reason.hpp).
class SolverFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class RightHandSide {
 public:
  virtual ~RightHandSide() = default;
  // v = F(x); v is resized by the callee. Throws SolverFailure.
  virtual void evaluate(const Points& x, Points& v, const EvaluationHint& hint) = 0;
  void operator()(const Points& x, Points& v) { evaluate(x, v, EvaluationHint{}); }
  // True when a probe's velocity is meant to be differenced against the last trajectory
  // evaluation's (λ ≠ 1: the second-kind solve cancels the base's solver error only there,
  // bie/viscosity_ratio.hpp): a power iteration must then start right after F at its own state.
  virtual bool probes_difference_against_last_evaluation() const { return false; }
};

// A right-hand side given as a function (tests, model problems).
class FunctionRhs final : public RightHandSide {
 public:
  explicit FunctionRhs(std::function<void(const Points& x, Points& v)> f) : f_(std::move(f)) {}
  void evaluate(const Points& x, Points& v, const EvaluationHint&) override { f_(x, v); }

 private:
  std::function<void(const Points& x, Points& v)> f_;
};

}  // namespace capsflow
