#pragma once
// The right-hand side of the capsule problem: positions x → node velocities v = dx/dt, through
// the stage pipeline of the paper (docs/time-integration.md §5.5):
//   wall (GSMB: rotation solve, warm-started) → R_s → M(x) q = R_s → v = v∞(x) − S[q].
// With fluid.volume_correction, v ← v − c n_i with c chosen so that the discrete flux
// Σ_e A_e n_e·(v0+v1+v2)/3 — exactly dV/dt of the polyhedron — is zero (volume_constraint.hpp):
// the O(h²) flux error of the P1 boundary integral (docs/time-integration.md §5.10) no longer
// accumulates into volume drift.
// With fluid.viscosity_ratio λ ≠ 1, v∞ − S[q] is the right-hand side of the second-kind equation
// (1 + λ)/2 u + (1 − λ) D[u] = v∞ − S[q] (bie/viscosity_ratio.hpp), solved before the volume
// correction; λ = 1 skips it (the same code path and numbers as without the key).
// Rotations are a slave variable (argmin of the bending + shear energy at given x): they are not
// integrated in time. Time schemes (stepping/) call it through RightHandSide::evaluate.
//
// Inner solvers never fail silently: a rotation Newton solve that does not converge is retried
// once from the nodal normals (counted in RhsCounters::rotation_fresh_starts); if that fails too,
// or the mass-matrix CG stops at its iteration cap, or the velocity is not finite, velocity()
// throws SolverFailure with a one-line description.
#include <array>
#include <memory>
#include <nlohmann/json_fwd.hpp>

#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/bie/viscosity_ratio.hpp"
#include "capsflow/core/phase_times.hpp"
#include "capsflow/core/rhs/capsules_dynamics.hpp"
#include "capsflow/core/rhs/rhs_counters.hpp"
#include "capsflow/core/rhs/right_hand_side.hpp"
#include "capsflow/core/rhs/wall_and_load.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

class CapsuleDynamics final : public CapsulesDynamics {
 public:
  // The wall is the scene's (rhs/wall_factory.hpp) unless one is given (tests).
  CapsuleDynamics(const Scene& scene, const SurfaceMesh& reference, int threads = 0,
                  std::unique_ptr<shell::Wall> wall = nullptr);

  // v(x) and, as by-products, the load q and R_s of this evaluation. Throws SolverFailure.
  // A probe (a point off the trajectory, Role::Probe) leaves the second-kind solve's warm start as
  // it is. The hint also says which kind of evaluation the counters book it under.
  void evaluate(const Points& x, Points& v, const EvaluationHint& hint) override;
  bool probes_difference_against_last_evaluation() const override { return viscosity_ != nullptr; }
  // The same; probe: Role::Probe, else a step's start state.
  void velocity(const Points& x, Points& v, bool probe = false) {
    evaluate(x, v, {probe ? EvaluationHint::Role::Probe : EvaluationHint::Role::Trajectory, 0});
  }

  // The wall's equilibrium and the load q at x without the fluid: what an output needs when it
  // writes no velocities. Not an evaluation (counted in RhsCounters::wall_solves). Throws SolverFailure.
  void solve_wall(const Points& x, const EvaluationHint& hint) override;

  // What an evaluation leaves for the next one (CapsulesDynamics::Carry, one wall): an output
  // between two steps (dense output) evaluates at an interpolated state and puts this back, so that
  // the trajectory does not depend on the outputs.
  Carry carry() const override;
  void restore(Carry c) override;

  // What the fluid solve carries from one trajectory evaluation to the next, for checkpoints (λ ≠ 1:
  // the second-kind solve's warm start and D̃[1]'s reuse records; nothing at λ = 1): the flags
  // under extra["fluid_state"], the vectors as the columns of `matrix`, one row per node (y, b and
  // the residual of the warm start, 3 columns each, then the 24 of the records). A run continued
  // from them continues bit for bit. load_fluid_state takes what fits this right-hand side and
  // leaves the rest to start afresh (a restart that switched the back end).
  void save_fluid_state(nlohmann::json& extra, Eigen::MatrixXd& matrix) const override;
  void load_fluid_state(const nlohmann::json& extra, const Eigen::MatrixXd& matrix) override;

  int capsules() const override { return 1; }
  const Points& load() const override { return wall_load_.load(); }
  shell::Wall& wall() { return wall_load_.wall(); }
  const shell::Wall& wall() const { return wall_load_.wall(); }
  shell::Wall& wall_of(int) override { return wall_load_.wall(); }
  const shell::Wall& wall_of(int) const override { return wall_load_.wall(); }
  const SingleLayer& single_layer() const override { return bie_; }
  // The second-kind solve (λ ≠ 1), or null.
  const ViscosityRatioSolver* viscosity_ratio_solver() const override { return viscosity_.get(); }
  // Seconds per phase, the boundary integral's phases included.
  PhaseTimes times() const override;
  const RhsCounters& counters() const override { return counters_; }
  const Mat3& gradient() const { return L_; }

 private:
  Mat3 L_;
  bool volume_correction_;
  Triangles tri_;
  Eigen::Index n_nodes_;
  WallAndLoad wall_load_;
  SingleLayer bie_;
  std::unique_ptr<ViscosityRatioSolver> viscosity_;  // λ ≠ 1 only
  Points u_, w_, nodal_area_normal_;                  // scratch, reused across calls
  PhaseTimes times_;                      // wall, load, other (the BIE keeps its own)
  RhsCounters counters_;
};

}  // namespace capsflow
