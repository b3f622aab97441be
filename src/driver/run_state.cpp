// The run's own entries of a checkpoint's "extra" JSON (the scheme adds its own: TimeStepper::save).
#include "simulation_impl.hpp"

namespace capsflow {

nlohmann::json RunState::extra() const {
  return {{"next_output", next_output}, {"next_checkpoint", next_checkpoint}, {"volume0", volume0},
          {"area0", area0}, {"wall_seconds", wall_seconds_before}, {"rejected_steps", rejected_steps},
          {"rhs_evaluations", rhs_evaluations}, {"gmres_per_eval_max", gmres_per_eval_max},
          {"tolerance_tightened", tolerance_tightened},
          {"auto_tolerance_rewind", rewind ? rewind->to_json() : nlohmann::json()},
          {"creases_seen_at", creases_seen_at ? nlohmann::json(*creases_seen_at) : nlohmann::json()}};
}

void RunState::set_extra(const nlohmann::json& e) {
  next_output = e.at("next_output");
  next_checkpoint = e.at("next_checkpoint");
  volume0 = e.at("volume0");
  area0 = e.at("area0");
  wall_seconds_before = e.at("wall_seconds");
  // Written since the RKC integrator (absent in older checkpoints: zero).
  rejected_steps = e.value("rejected_steps", 0L);
  rhs_evaluations = e.value("rhs_evaluations", 0L);
  gmres_per_eval_max = e.value("gmres_per_eval_max", 0.0);  // since fluid.viscosity_ratio
  tolerance_tightened = e.value("tolerance_tightened", false);  // since time.tolerance = "auto"
  if (e.contains("auto_tolerance_rewind") && !e.at("auto_tolerance_rewind").is_null())
    rewind = AutoToleranceRewind::from_json(e.at("auto_tolerance_rewind"));
  if (e.contains("creases_seen_at") && !e.at("creases_seen_at").is_null())  // since ROCK4's looser past the creases
    creases_seen_at = e.at("creases_seen_at").get<double>();
}

nlohmann::json AutoToleranceRewind::to_json() const {
  return {{"t", t}, {"steps", steps}, {"rhs_evaluations", evaluations}, {"wall_seconds", seconds}};
}

AutoToleranceRewind AutoToleranceRewind::from_json(const nlohmann::json& j) {
  return {j.at("t").get<double>(), j.at("steps").get<long>(), j.at("rhs_evaluations").get<long>(),
          j.at("wall_seconds").get<double>()};
}

}  // namespace capsflow
