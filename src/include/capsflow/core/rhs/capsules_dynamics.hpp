#pragma once
// What a run (driver/) needs of the right-hand side of its capsules, one (CapsuleDynamics) or
// several (SuspensionDynamics): the velocity F(x), each capsule's wall, the load q of the last
// evaluation, the wall alone for outputs, what an evaluation carries to the next (put back after an
// output between steps), the fluid solve's restart state, the single layer's far field, counters
// and phase times. Positions are the union of the capsules' nodes (geometry/surface_set.hpp); one
// capsule is the union of one.
#include <nlohmann/json_fwd.hpp>
#include <vector>

#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/bie/viscosity_ratio.hpp"
#include "capsflow/core/phase_times.hpp"
#include "capsflow/core/rhs/rhs_counters.hpp"
#include "capsflow/core/rhs/right_hand_side.hpp"
#include "capsflow/shell/wall.hpp"

namespace capsflow {

class CapsulesDynamics : public RightHandSide {
 public:
  // What an evaluation leaves for the next one: each wall's warm start (its state), the load, the
  // second-kind solve's warm start (λ ≠ 1).
  struct Carry {
    std::vector<Eigen::VectorXd> walls;
    Points load;
    ViscosityRatioSolver::WarmStart viscosity;
    Points channel_traction;  // a channel wall's traction (its solve's warm start); empty without
  };

  virtual int capsules() const = 0;
  virtual shell::Wall& wall_of(int k) = 0;
  virtual const shell::Wall& wall_of(int k) const = 0;
  virtual const Points& load() const = 0;  // of the last evaluation (or solve_wall), the union's rows
  // The walls' equilibrium and the load q at x without the fluid: what an output needs when it
  // writes no velocities. Not an evaluation (counted in RhsCounters::wall_solves). Throws SolverFailure.
  virtual void solve_wall(const Points& x, const EvaluationHint& hint) = 0;
  virtual Carry carry() const = 0;
  virtual void restore(Carry c) = 0;
  // What the fluid solve carries from one trajectory evaluation to the next, for checkpoints
  // (CapsuleDynamics::save_fluid_state: the second-kind solve's at λ ≠ 1; ChannelDynamics's: the
  // wall's traction; nothing for one capsule at λ = 1).
  virtual void save_fluid_state(nlohmann::json& extra, Eigen::MatrixXd& matrix) const = 0;
  virtual void load_fluid_state(const nlohmann::json& extra, const Eigen::MatrixXd& matrix) = 0;
  // The single layer over every capsule: its far field's back end, order, tolerance and checks.
  virtual const SingleLayer& single_layer() const = 0;
  virtual const ViscosityRatioSolver* viscosity_ratio_solver() const = 0;  // λ ≠ 1, or null
  virtual PhaseTimes times() const = 0;
  virtual const RhsCounters& counters() const = 0;
};

}  // namespace capsflow
