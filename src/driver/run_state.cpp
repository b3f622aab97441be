// The run's own entries of a checkpoint's "extra" JSON (the time plan and the scheme add theirs:
// write_checkpoint, TimeStepper::save).
#include "simulation_impl.hpp"

namespace capsflow {

nlohmann::json RunState::extra() const {
  return {{"next_output", next_output}, {"next_checkpoint", next_checkpoint}, {"volume0", volume0},
          {"area0", area0}, {"wall_seconds", wall_seconds_before}, {"rejected_steps", rejected_steps},
          {"rhs_evaluations", rhs_evaluations}, {"gmres_per_eval_max", gmres_per_eval_max},
          {"tolerance_tightened", tolerance_tightened},
          {"auto_tolerance_rewind", rewind ? rewind->to_json() : nlohmann::json()},
          {"creases_seen_at", creases_seen_at ? nlohmann::json(*creases_seen_at) : nlohmann::json()},
          {"centroid_frame", {centroid_frame[0], centroid_frame[1], centroid_frame[2]}},
          {"centroid_lab", {centroid_lab[0], centroid_lab[1], centroid_lab[2]}}};
}

void RunState::set_extra(const nlohmann::json& e) {
  next_output = e.at("next_output");
  next_checkpoint = e.at("next_checkpoint");
  volume0 = e.at("volume0");
  area0 = e.at("area0");
  wall_seconds_before = e.at("wall_seconds");
  rejected_steps = e.at("rejected_steps");
  rhs_evaluations = e.at("rhs_evaluations");
  gmres_per_eval_max = e.at("gmres_per_eval_max");
  tolerance_tightened = e.at("tolerance_tightened");
  if (!e.at("auto_tolerance_rewind").is_null()) rewind = AutoToleranceRewind::from_json(e.at("auto_tolerance_rewind"));
  if (!e.at("creases_seen_at").is_null()) creases_seen_at = e.at("creases_seen_at").get<double>();
  for (int k = 0; k < 3; ++k) {
    centroid_frame[k] = e.at("centroid_frame").at(k).get<double>();
    centroid_lab[k] = e.at("centroid_lab").at(k).get<double>();
  }
}

CreaseHistory RunState::creases() const {
  CreaseHistory h;
  h.seen_at = creases_seen_at;
  h.tightened = tolerance_tightened;
  if (rewind) h.tight_until = rewind->t;
  return h;
}

nlohmann::json AutoToleranceRewind::to_json() const {
  return {{"t", t}, {"steps", steps}, {"rhs_evaluations", evaluations}, {"wall_seconds", seconds}};
}

AutoToleranceRewind AutoToleranceRewind::from_json(const nlohmann::json& j) {
  return {j.at("t").get<double>(), j.at("steps").get<long>(), j.at("rhs_evaluations").get<long>(),
          j.at("wall_seconds").get<double>()};
}

}  // namespace capsflow
