// time.tolerance = "auto" (stepping/auto_tolerance.hpp, docs/time-integration.md §5.8, §5.11).
// RKC2 runs at the loose tolerance until the wall folds at the mesh scale (the health monitors' own
// criterion: grid-scale oscillation above its threshold) into creases (facet angles above
// kAutoToleranceCreaseDeg); then the run starts again from t = 0 at the folded tolerance, in the
// same folder, as a fresh run at that tolerance would — so up to the crease time its outputs are
// that run's, bit for bit. Past the time where the loose pass saw the creases it goes back to the
// loose tolerance: once the creases have formed, the dynamics no longer amplify the error.
// ROCK4 needs no rewind (its tolerance up to the creases follows the mesh from t = 0): where it
// sees the same creases it loosens, for the same reason.
#include <spdlog/spdlog.h>

#include <fmt/core.h>

#include "capsflow/core/stepping/auto_tolerance.hpp"
#include "simulation_impl.hpp"

namespace capsflow {

bool Simulation::Impl::wall_creased() const {
  return health->folding() && health->last().roughness.facet_angle_max > kAutoToleranceCreaseDeg;
}

bool Simulation::Impl::tolerance_must_tighten() const {
  return scene.time.tolerance_auto && scene.time.scheme == TimeScheme::Rkc && scene.time.dt_auto && !st.tolerance_tightened &&
         wall_creased();
}

// A state function, so that a restart builds the scheme with the tolerance the uninterrupted run
// had there: tight after a rewind until the loose pass's crease time, and for good when the run
// could not rewind (a restart into a new folder, below).
bool Simulation::Impl::folded_tolerance_in_force() const {
  return st.tolerance_tightened && !(st.rewind && st.t >= st.rewind->t);
}

Scene Simulation::Impl::stepping_scene() const {
  Scene s = scene;
  if (s.time.tolerance_auto && folded_tolerance_in_force()) s.time.tolerance = kAutoToleranceFolded;
  if (s.time.tolerance_auto && s.time.scheme == TimeScheme::Rock4 && st.creases_seen_at)
    s.time.tolerance = auto_tolerance_rock4_past_creases(scene.time.tolerance);  // the set-up resolved the one before
  return s;
}

// Called after every accepted step (before its outputs and checkpoint): the step that passes the
// crease time hands the rest of the run to the loose tolerance.
void Simulation::Impl::relax_tolerance_past_creases(double t_step_start) {
  if (!scene.time.tolerance_auto || !st.rewind) return;  // a rewind implies the creases were seen
  if (!(t_step_start < st.rewind->t && st.t >= st.rewind->t)) return;
  if (!stepper->set_tolerance(kAutoToleranceLoose)) return;
  spdlog::info("γ̇t = {:.3g}: past the creases (seen at {:.3g} in the discarded pass); time.tolerance \"auto\" is back at {:g}",
               st.t, st.rewind->t, kAutoToleranceLoose);
}

// Called after every accepted step: the step where ROCK4's run first sees the creases hands the
// rest of the run (and any restart from a later checkpoint) to the looser tolerance.
void Simulation::Impl::relax_rock4_tolerance_at_creases() {
  if (!scene.time.tolerance_auto || scene.time.scheme != TimeScheme::Rock4 || !scene.time.dt_auto) return;
  if (st.creases_seen_at || !wall_creased()) return;
  st.creases_seen_at = st.t;
  const double tol = stepping_scene().time.tolerance;
  if (tol == scene.time.tolerance || !stepper->set_tolerance(tol)) return;  // 1 280 elements and coarser: unchanged
  spdlog::info("γ̇t = {:.3g}: the wall creases at the mesh scale (facet angles up to {:.0f}°); once formed, creases no longer "
               "amplify the error: time.tolerance \"auto\" goes from {:g} to {:g} (docs/time-integration.md §5.11)",
               st.t, health->last().roughness.facet_angle_max, scene.time.tolerance, tol);
}

bool Simulation::Impl::tighten_tolerance() {
  if (restart.new_folder) {  // this folder starts at the checkpoint: its beginning is the parent run's
    spdlog::warn("the wall creases at the mesh scale at γ̇t = {:.3g}: time.tolerance \"auto\" tightens from {:g} to {:g} from here "
                 "on, but this run folder continues a checkpoint of γ̇t = {:g}, so its start was integrated at {:g}; for D_ij "
                 "within 1e-4 throughout, run from t = 0 (docs/time-integration.md §5.8)",
                 st.t, kAutoToleranceLoose, kAutoToleranceFolded, t_segment_start, kAutoToleranceLoose);
    st.tolerance_tightened = true;
    stepper = make_time_stepper(stepping_scene(), ref.triangles, st.volume0, st.x);
    return false;
  }
  const AutoToleranceRewind discarded{st.t, st.step, rhs_evaluations(), wall_seconds()};
  spdlog::warn("the wall creases at the mesh scale at γ̇t = {:.3g} (facet angles up to {:.0f}°): time.tolerance \"auto\" "
               "starts the run again from t = 0 at {:g} up to γ̇t = {:.3g} and {:g} after, since the error made before the "
               "folds is amplified while they form (docs/time-integration.md §5.8); {} steps, {} evaluations and {:.1f} s "
               "are discarded (time.scheme = \"rock4\" needs no rewind and costs less on creasing walls, §5.11)",
               discarded.t, health->last().roughness.facet_angle_max, kAutoToleranceFolded, discarded.t, kAutoToleranceLoose,
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
  last_tank_treading = std::numeric_limits<double>::quiet_NaN();
  output_mark = RhsCounters{};
  make_parts();
  start_at_reference();
  out = std::make_unique<io::ResultsWriter>(folder, ref, metadata());
  stepper = make_time_stepper(stepping_scene(), ref.triangles, st.volume0, st.x);
  observe_health();
  effort_mark = dyn->counters();
  write_first_output();
  t_segment_start = 0;
  return true;
}

}  // namespace capsflow
