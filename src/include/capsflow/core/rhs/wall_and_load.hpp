#pragma once
// One capsule's wall stage of an evaluation (docs/time-integration.md §5.5): the wall's equilibrium
// at x — GSMB: the rotation solve, warm-started from the hint's stage predictor, retried once
// from the nodal normals — with its load R_s, then M(x) q = R_s. Throws SolverFailure when the
// rotation solve fails twice or the mass-matrix CG stops at its cap.
#include <memory>

#include "capsflow/core/phase_times.hpp"
#include "capsflow/core/rhs/rhs_counters.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "capsflow/shell/load_recovery.hpp"
#include "capsflow/shell/wall.hpp"

namespace capsflow {

class WallAndLoad {
 public:
  // The wall is the scene's (rhs/wall_factory.hpp) unless one is given (tests).
  WallAndLoad(const Scene& scene, const SurfaceMesh& reference, std::unique_ptr<shell::Wall> wall = nullptr);

  // The load q at x (load()), counted in `counters` under the hint's kind; the seconds since
  // `clock`'s last lap go to Phase::Wall, the mass solve's to Phase::Load of `times`. A given
  // `extra_force` (nodal forces applied to the wall from outside, e.g. a repulsion) enters
  // R_s = ∂E/∂x as −extra_force before M q = R_s.
  void solve(const Points& x, const EvaluationHint& hint, RhsCounters& counters, PhaseTimes& times, Stopwatch& clock,
             const Points* extra_force = nullptr);

  const Points& load() const { return q_; }
  void set_load(Points q) { q_ = std::move(q); }
  shell::Wall& wall() { return *wall_; }
  const shell::Wall& wall() const { return *wall_; }

 private:
  std::unique_ptr<shell::Wall> wall_;
  shell::LoadRecovery mass_;
  Points R_, q_;
  shell::WallStats last_stats_;
};

}  // namespace capsflow
