#include "capsflow/core/rhs/wall_and_load.hpp"

#include <fmt/core.h>

#include "capsflow/core/rhs/wall_factory.hpp"

namespace capsflow {

WallAndLoad::WallAndLoad(const Scene& scene, const SurfaceMesh& reference, std::unique_ptr<shell::Wall> wall)
    : wall_(wall ? std::move(wall) : make_wall(scene, reference)), mass_(reference.triangles, reference.num_nodes()) {}

void WallAndLoad::solve(const Points& x, const EvaluationHint& hint, RhsCounters& counters, PhaseTimes& times,
                        Stopwatch& clock, const Points* extra_force) {
  SolveCounts& by_kind = counters.by_kind[static_cast<std::size_t>(evaluation_kind(hint))];
  ++by_kind.evaluations;
  shell::Wall::WarmStart warm;
  static_assert(shell::Wall::WarmStart::kSlots == StagePredictor::kSlots &&
                shell::Wall::WarmStart::kTerms == StagePredictor::kTerms);
  const StagePredictor& p = hint.predictor;
  warm.keep_start = p.keep_start, warm.keep = p.keep, warm.terms = p.terms, warm.slot = p.slot, warm.weight = p.weight;
  for (int attempt = 0;; ++attempt) {
    wall_->set_warm_start(warm);
    warm.keep_start = -1, warm.terms = 0;  // a retry starts from the nodal normals (and keeps its solution)
    wall_->forces(x, R_, &last_stats_);
    counters.newton_iterations += last_stats_.newton_iterations;
    counters.cg_iterations += last_stats_.cg_iterations;
    by_kind.newton_iterations += last_stats_.newton_iterations;
    by_kind.cg_iterations += last_stats_.cg_iterations;
    if (last_stats_.converged) break;
    if (attempt == 1) {
      clock.lap(times, Phase::Wall);
      throw SolverFailure(fmt::format("rotation Newton did not converge (residual {:.1e} rad after {} iterations, "
                                      "also from a fresh start)", last_stats_.residual, last_stats_.newton_iterations));
    }
    ++counters.rotation_fresh_starts;
    wall_->restart_rotations(x);
  }
  if (extra_force) R_ -= *extra_force;  // R_s = ∂E/∂x: a force f on the nodes enters as −f
  clock.lap(times, Phase::Wall);

  counters.mass_cg_iterations += mass_.solve(x, R_, q_);
  clock.lap(times, Phase::Load);
  if (!mass_.last_converged())
    throw SolverFailure(fmt::format("mass-matrix CG stopped at its iteration cap ({} iterations, relative residual {:.1e})",
                                    shell::LoadRecovery::kMaxIterations, mass_.last_relative_residual()));
}

}  // namespace capsflow
