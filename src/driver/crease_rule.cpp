// What the run does where the wall creases at the mesh scale: the time plan's CreaseAction
// (stepping/time_plan.hpp, docs/time-integration.md §5.3 and §5.4). The creases are the health
// monitors' grid-scale folding with facet angles above kAutoToleranceCreaseDeg.
//   Loosen  from the step that first sees them, the plan's looser crease_tolerance: once formed,
//           creases no longer amplify the error.
//   Rewind  the run starts again from t = 0 in the same folder at the tight crease_tolerance, as a
//           fresh run at that tolerance would — so up to the crease time its outputs are that
//           run's, bit for bit — and past the crease time of the discarded pass it takes the plan's
//           first tolerance again. Why a rewind and not a switch: the error made before the folds
//           is amplified while they form (auto_tolerance.hpp).
#include <spdlog/spdlog.h>

#include <fmt/core.h>

#include <algorithm>

#include "capsflow/core/stepping/auto_tolerance.hpp"
#include "simulation_impl.hpp"

namespace capsflow {

bool Simulation::Impl::wall_creased() const {
  for (const CapsuleWatch& w : watch)  // any capsule's wall
    if (w.health->folding() && w.health->last().roughness.facet_angle_max > kAutoToleranceCreaseDeg) return true;
  return false;
}

double Simulation::Impl::largest_facet_angle() const {
  double a = 0;
  for (const CapsuleWatch& w : watch) a = std::max(a, w.health->last().roughness.facet_angle_max);
  return a;
}

// Called after every accepted step, before its outputs and checkpoint.
bool Simulation::Impl::follow_crease_rule(bool health_stop) {
  switch (plan.at_creases) {
    case CreaseAction::Rewind:
      if (!health_stop && !st.tolerance_tightened && wall_creased() && rewind_to_start()) return true;
      break;
    case CreaseAction::Loosen:
      if (!st.creases_seen_at && wall_creased()) st.creases_seen_at = st.t;
      break;
    case CreaseAction::None: break;
  }
  follow_tolerance_in_force();
  return false;
}

void Simulation::Impl::follow_tolerance_in_force() {
  const double tol = tolerance_in_force();
  if (tol == stepper_tolerance || !stepper->set_tolerance(tol)) return;
  const std::string why =
      plan.at_creases == CreaseAction::Loosen
          ? fmt::format("the wall creases at the mesh scale (facet angles up to {:.0f}°); once formed, creases no longer "
                        "amplify the error", largest_facet_angle())
      : st.rewind ? fmt::format("past the creases, seen at {:.3g} in the discarded pass", st.rewind->t)
                  : std::string("the wall creases at the mesh scale");
  spdlog::info("γ̇t = {:.3g}: {}: time.tolerance goes from {:g} to {:g} (docs/time-integration.md §5.3, §5.4)", st.t, why,
               stepper_tolerance, tol);
  stepper_tolerance = tol;
}

bool Simulation::Impl::rewind_to_start() {
  st.tolerance_tightened = true;
  if (restart.new_folder) {  // this folder starts at the checkpoint: its beginning is the parent run's
    spdlog::warn("the wall creases at the mesh scale at γ̇t = {:.3g}: the tolerance tightens to {:g} from here on, but this run "
                 "folder continues a checkpoint of γ̇t = {:g}, so its start was integrated at {:g}; for D_ij within 1e-4 "
                 "throughout, run from t = 0 (docs/time-integration.md §5.3)",
                 st.t, plan.crease_tolerance, t_segment_start, plan.tolerance);
    return false;
  }
  const AutoToleranceRewind discarded{st.t, st.step, rhs_evaluations(), wall_seconds()};
  spdlog::warn("the wall creases at the mesh scale at γ̇t = {:.3g} (facet angles up to {:.0f}°): the run starts again from "
               "t = 0 at time.tolerance {:g} up to γ̇t = {:.3g} and {:g} after, since the error made before the folds is "
               "amplified while they form (docs/time-integration.md §5.3); {} steps, {} evaluations and {:.1f} s are discarded",
               discarded.t, largest_facet_angle(), plan.crease_tolerance, discarded.t, plan.tolerance,
               discarded.steps, discarded.evaluations, discarded.seconds);
  // Everything a fresh run would start with; the run's cost so far stays counted.
  out.reset();
  stepper.reset();
  dyn.reset();
  st = RunState{};
  st.tolerance_tightened = true;
  st.rewind = discarded;
  st.rhs_evaluations = discarded.evaluations;
  st.wall_seconds_before = discarded.seconds;
  segment_clock.restart();
  steps_this_segment = 0;
  consecutive_rejections = 0;
  consecutive_solver_failures = 0;
  last_output_t = -1;
  output_mark = RhsCounters{};
  make_parts();
  start_at_reference();
  out = new_results_writer();
  make_stepper();
  observe_health();
  effort_mark = dyn->counters();
  write_first_output();
  t_segment_start = 0;
  return true;
}

}  // namespace capsflow
