#pragma once
// What the inner solvers of a right-hand side did, summed over evaluations, and by kind of
// evaluation (the hint's role and stage).
#include <array>

#include "capsflow/core/rhs/right_hand_side.hpp"

namespace capsflow {

// What the rotation solve did for one kind of evaluation (RhsCounters::by_kind).
struct SolveCounts {
  long evaluations = 0, newton_iterations = 0, cg_iterations = 0;
  long gmres_iterations = 0;  // the λ ≠ 1 solve's (double-layer applications after its set-up)
};

// The kinds of evaluation counted apart, from the hint: the step's start state (stage 0), a later
// stage of a step started from the last evaluation's solution, one started from the scheme's stage
// predictor (EvaluationHint::predictor), a spectral-radius probe, the run's output at the current state.
enum class EvaluationKind { StepStart, Stage, PredictedStage, Probe, Output };
inline constexpr std::array<const char*, 5> kEvaluationKindNames = {"step_start", "stage", "predicted_stage", "probe",
                                                                    "output"};
inline EvaluationKind evaluation_kind(const EvaluationHint& hint) {
  switch (hint.role) {
    case EvaluationHint::Role::Probe: return EvaluationKind::Probe;
    case EvaluationHint::Role::Output: return EvaluationKind::Output;
    case EvaluationHint::Role::Trajectory: break;
  }
  if (hint.stage == 0) return EvaluationKind::StepStart;
  return hint.predictor.terms > 0 ? EvaluationKind::PredictedStage : EvaluationKind::Stage;
}

// What the inner solvers of the right-hand side did, summed over evaluations.
struct RhsCounters {
  long evaluations = 0;
  long newton_iterations = 0, cg_iterations = 0, mass_cg_iterations = 0;
  long rotation_fresh_starts = 0;  // Newton solves retried from the nodal normals
  long gmres_iterations = 0;       // λ ≠ 1: double-layer applications of the second-kind solves
  long wall_solves = 0;            // wall and load without the fluid (solve_wall: outputs without velocities)
  std::array<SolveCounts, kEvaluationKindNames.size()> by_kind;  // the rotation solve by EvaluationKind
};

}  // namespace capsflow
