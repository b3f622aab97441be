// time.tolerance = "auto" (stepping/auto_tolerance.hpp, docs/time-integration.md §5.8): RKC runs at
// the loose tolerance until the wall folds at the mesh scale (the health monitors' own criterion:
// grid-scale oscillation above its threshold) into creases (facet angles above
// kAutoToleranceCreaseDeg); then the run starts again from t = 0 at the folded tolerance, in the
// same folder, as a fresh run at that tolerance would — so its outputs are that run's, bit for
// bit, and only its cost (the discarded part, in summary.json) differs.
#include <spdlog/spdlog.h>

#include <fmt/core.h>

#include "capsflow/core/stepping/auto_tolerance.hpp"
#include "simulation_impl.hpp"

namespace capsflow {

bool Simulation::Impl::tolerance_must_tighten() const {
  return scene.time.tolerance_auto && scene.time.scheme == TimeScheme::Rkc && scene.time.dt_auto && !st.tolerance_tightened &&
         health->folding() && health->last().roughness.facet_angle_max > kAutoToleranceCreaseDeg;
}

Scene Simulation::Impl::stepping_scene() const {
  Scene s = scene;
  if (s.time.tolerance_auto && st.tolerance_tightened) s.time.tolerance = kAutoToleranceFolded;
  return s;
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
               "starts the run again from t = 0 at {:g} instead of {:g}, since the error made before the folds is "
               "amplified while they form (docs/time-integration.md §5.8); {} steps, {} evaluations and {:.1f} s are "
               "discarded",
               discarded.t, health->last().roughness.facet_angle_max, kAutoToleranceFolded, kAutoToleranceLoose,
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
