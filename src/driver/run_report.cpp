// What the run tells: the status line (and the caller's progress callback), the per-phase timing
// table, summary.json (docs/scene-and-output.md §3.5) and the closing log.
#include <sys/resource.h>

#include <spdlog/spdlog.h>

#include <cmath>
#include <fmt/core.h>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/geometry/rear_pole.hpp"
#include "capsflow/core/io/version.hpp"
#include "simulation_impl.hpp"

namespace capsflow {

namespace {

std::string hms(double s) {
  if (!std::isfinite(s) || s > 1e9) return "?";
  const long t = static_cast<long>(s + 0.5);
  return t >= 3600 ? fmt::format("{}h{:02}m", t / 3600, (t / 60) % 60) : fmt::format("{}m{:02}s", t / 60, t % 60);
}

// The process's peak resident memory so far (getrusage maxrss, kB on Linux), in MB.
double peak_rss_mb() {
  rusage u{};
  return getrusage(RUSAGE_SELF, &u) == 0 ? static_cast<double>(u.ru_maxrss) / 1024.0 : 0.0;
}

}  // namespace

namespace {
// The progress line's health: one capsule's status, or "ok" and each ailing capsule's ("c2 folds").
std::string health_status(const std::vector<CapsuleWatch>& watch, const SurfaceGapWatch* gap, const WallGapWatch* wall_gap) {
  if (watch.size() == 1) {
    const std::string one = watch[0].health->status();
    if (!wall_gap || !wall_gap->active()) return one;
    return one == "ok" ? "surface_gap" : one + ", surface_gap";
  }
  std::string s;
  for (std::size_t k = 0; k < watch.size(); ++k)
    if (const std::string one = watch[k].health->status(); one != "ok") s += fmt::format("{}c{} {}", s.empty() ? "" : ", ", k + 1, one);
  if (gap && gap->active()) s += std::string(s.empty() ? "" : ", ") + "surface_gap";
  return s.empty() ? "ok" : s;
}
}  // namespace

void Simulation::Impl::report_progress(bool force) {
  if (!force && report_clock.seconds() < opt.progress_interval) return;
  report_clock.restart();
  const double seg = segment_clock.seconds();
  const long evals = dyn->counters().evaluations;
  const double per_eval = evals ? seg / static_cast<double>(evals) : 0;
  const double t_end = scene.time.t_end;
  // ETA from the simulated time per wall second of this segment (an error-controlled step varies).
  const double done = st.t - t_segment_start;
  const double eta = done > 0 ? seg * (t_end - st.t) / done : NAN;
  const double drift = enclosed_volume(SurfaceMesh{st.x, ref.triangles}) / st.volume0 - 1;
  const std::string status = health_status(watch, gap.get(), wall_gap.get());
  spdlog::info("step {:>7}  t {:.4f}/{:g} ({:5.1f}%)  dt {:.2e}  {} rej {:>3}  evals {:>7} ({:.1f} ms)  ETA {}  dV/V {:+.1e}  steady {:.1e} (tol {:.0e})  health {}",
               st.step, st.t, t_end, 100 * st.t / t_end, st.dt, stepper->status(), st.rejected_steps, rhs_evaluations(),
               1e3 * per_eval, hms(eta), drift, steady->measure(), scene.time.steady_tol, status);
  if (opt.on_progress) opt.on_progress({st.step, st.t, t_end, st.dt, rhs_evaluations(), wall_seconds(), eta, drift, steady->measure(), status});
}

nlohmann::json Simulation::Impl::timing_table() const {
  const PhaseTimes p = dyn->times();
  const RhsCounters& n = dyn->counters();
  const double total = wall_seconds() - st.wall_seconds_before;
  // "other" is what the phases do not cover (the scheme's updates, diagnostics, output).
  // cpu_seconds: the same phases in CPU seconds of all threads (CPU/wall = busy threads).
  const double total_cpu = segment_clock.cpu_seconds();
  nlohmann::json phases = nlohmann::json::object(), cpu = nlohmann::json::object();
  double known = 0, known_cpu = 0;
  for (std::size_t i = 0; i < kPhaseNames.size(); ++i) {
    const Phase ph = static_cast<Phase>(i);
    if (ph == Phase::Other) continue;
    phases[kPhaseNames[i]] = p[ph];
    cpu[kPhaseNames[i]] = p.cpu(ph);
    known += p[ph];
    known_cpu += p.cpu(ph);
  }
  phases[kPhaseNames[static_cast<std::size_t>(Phase::Other)]] = std::max(0.0, total - known);
  cpu[kPhaseNames[static_cast<std::size_t>(Phase::Other)]] = std::max(0.0, total_cpu - known_cpu);
  nlohmann::json table = {{"total_seconds", total}, {"total_cpu_seconds", total_cpu}, {"threads", threads},
          {"steps", steps_this_segment}, {"rhs_evaluations", n.evaluations},
          {"seconds_per_evaluation", n.evaluations ? total / static_cast<double>(n.evaluations) : 0},
          {"seconds_per_step", steps_this_segment ? total / static_cast<double>(steps_this_segment) : 0},
          {"phases", phases}, {"cpu_seconds", cpu},
          {"iterations", {{"newton", n.newton_iterations}, {"rotation_cg", n.cg_iterations}, {"mass_cg", n.mass_cg_iterations},
                          {"rotation_fresh_starts", n.rotation_fresh_starts}, {"wall_solves", n.wall_solves}}}};
  if (dyn->viscosity_ratio_solver()) table["iterations"]["gmres"] = n.gmres_iterations;
  // The rotation solve by kind of evaluation: what a stage costs against a probe or an output.
  nlohmann::json by_kind = nlohmann::json::object();
  for (std::size_t k = 0; k < kEvaluationKindNames.size(); ++k) {
    const SolveCounts& c = n.by_kind[k];
    if (c.evaluations == 0) continue;
    by_kind[kEvaluationKindNames[k]] = {{"evaluations", c.evaluations}, {"newton", c.newton_iterations},
                                         {"rotation_cg", c.cg_iterations}};
    if (dyn->viscosity_ratio_solver()) by_kind[kEvaluationKindNames[k]]["gmres"] = c.gmres_iterations;
  }
  table["iterations"]["by_evaluation"] = by_kind;
  return table;
}

// summary.json without stop_reason and timing (Simulation::finish adds them).
nlohmann::json Simulation::Impl::capsule_summary(int k) const {
  const CapsuleWatch& w = watch.at(static_cast<std::size_t>(k));
  const ShapeDiagnostics& s = w.last_shape;
  const Vec3 c = capsules() == 1 ? st.centroid_lab : capsule_centroid_lab(st.centroid_lab, st.centroid_frame, st.x, k);
  const Vec3& u = w.last_velocity;
  const nlohmann::json velocity = u.allFinite() ? nlohmann::json{u[0], u[1], u[2]} : nlohmann::json();
  nlohmann::json entry = {{"centroid", {c[0], c[1], c[2]}},
          {"D12", s.D.D12}, {"D13", s.D.D13}, {"D23", s.D.D23},
          {"L", {s.L[0], s.L[1], s.L[2]}}, {"Le", {s.Le[0], s.Le[1], s.Le[2]}},
          {"area", s.area}, {"volume", s.volume}, {"volume_drift", s.volume / w.volume0 - 1},
          {"D_flow", w.last_plane_shape.D}, {"theta", w.last_plane_shape.theta * 180 / M_PI},
          {"tank_treading", std::isfinite(w.last_tank_treading) ? nlohmann::json(w.last_tank_treading) : nlohmann::json()},
          {"health", w.health->summary()}};
  if (capsules() > 1) entry["velocity"] = velocity;  // the last row's (one capsule: not computed)
  return entry;
}

nlohmann::json Simulation::Impl::summary() const {
  nlohmann::json summary = {
      {"t", st.t}, {"steps", st.step}, {"steady", steady->steady()},
      {"wall_seconds", wall_seconds()}, {"elements", ref.num_elements()}, {"nodes", ref.num_nodes()},
      {"backend", to_string(dyn->single_layer().backend())}, {"backend_reason", dyn->single_layer().backend_reason()},
      {"fmm_order", dyn->single_layer().fmm_order()}, {"fmm_leaf_size", dyn->single_layer().fmm_leaf_size()},
      {"far_field_tolerance", dyn->single_layer().far_field_tolerance()},
      {"threads", threads},
      {"steady_measure", steady->measure()}, {"scene", to_json(scene)},
      {"version", version_string()}, {"git", git_hash()},
      {"scheme", to_string(plan.scheme)}, {"time_plan", plan.to_json()}, {"rhs_evaluations", rhs_evaluations()},
      {"rejected_steps", st.rejected_steps}};
  stepper->summarize(summary, st.x, st.step);
  if (plan.error_control)  // the error-controlled step's tolerance
    summary["time_tolerance"] = {{"auto", plan.tolerance_auto},
                                 {"in_force", tolerance_in_force()},
                                 {"rewind", st.rewind ? st.rewind->to_json() : nlohmann::json()},
                                 {"creases_seen_at", st.creases_seen_at ? nlohmann::json(*st.creases_seen_at) : nlohmann::json()}};
  // Each capsule's shape at the last output (the flow-plane observables: docs/conventions.md §5.6;
  // θ in degrees); one capsule's also at the top level, where scripts of one capsule read them.
  summary["capsules"] = nlohmann::json::array();
  for (int k = 0; k < capsules(); ++k) summary["capsules"].push_back(capsule_summary(k));
  if (capsules() == 1) {
    for (const auto& [key, value] : summary["capsules"][0].items()) summary[key] = value;
  } else {
    summary["volume_drift"] = enclosed_volume(SurfaceMesh{st.x, ref.triangles}) / st.volume0 - 1;
    summary["surface_gap"] = gap->summary();
    summary["contact"] = {{"repulsion_range", scene.contact.repulsion_range},
                          {"repulsion_strength", scene.contact.repulsion_strength}};
  }
  if (dyn->viscosity_ratio_solver()) {
    const DoubleLayerDiagnostics D = dyn->viscosity_ratio_solver()->double_layer().diagnostics();
    summary["viscosity_ratio"] = {{"lambda", scene.fluid.viscosity_ratio},
                                  {"gmres_per_eval_max", st.gmres_per_eval_max},
                                  {"double_layer_backend", to_string(D.backend)},
                                  {"double_layer_backend_reason", D.backend_reason},
                                  // where the second-kind solve's time goes (this segment's operator)
                                  {"double_layer_set_ups", D.setups},
                                  {"double_layer_set_up_seconds", D.setup_seconds},
                                  {"double_layer_applications", D.applications},
                                  {"double_layer_inexact_applications", D.inexact_applications},
                                  {"double_layer_apply_seconds", D.apply_seconds},
                                  {"gmres_bound_restarts", dyn->viscosity_ratio_solver()->bound_restarts()}};
    // The inexact Krylov steps by the FMM order they took (docs/boundary-integral.md §4.8.3).
    nlohmann::json by_order = nlohmann::json::object();
    for (const auto& t : D.inexact_fmm_uses) by_order[std::to_string(t.order)] = t.applications;
    if (!by_order.empty()) summary["viscosity_ratio"]["double_layer_inexact_by_fmm_order"] = by_order;
    // D̃[1]'s reused error term (docs/boundary-integral.md §4.7.5), this segment's operator.
    if (D.reuses_identity_term)
      summary["viscosity_ratio"]["identity_term"] = {{"refreshes", D.identity.refreshes},
                                                     {"max_drift", D.identity.max_drift},
                                                     {"max_drift_over_sampled", D.identity.max_drift_over_sampled},
                                                     {"max_reused_sampled_drift", D.identity.max_reused_drift},
                                                     {"samples", D.identity.samples.size()},
                                                     {"refresh_fmm_order", D.refresh_fmm_order}};
  }
  if (channel) {  // docs/channel.md §4
    const ChannelFlow& c = channel->channel();
    const SurfaceMesh& w = channel->channel_wall().mesh();
    const double ratio = channel->axial_velocity() / c.mean_velocity;
    summary["velocity_ratio"] = ratio;
    summary["pressure_drop"] = channel->pressure_drop();
    summary["rear_curvature"] = rear_pole_curvature(st.x, ref.triangles);
    summary["channel"] = {{"shape", to_string(scene.channel.shape)},
                          {"radius", c.geometry.radius},
                          {"length", c.geometry.length},
                          {"element_size", c.geometry.element_size},
                          {"wall_nodes", w.num_nodes()},
                          {"wall_elements", w.num_elements()},
                          {"velocity_ratio", ratio},
                          {"pressure_drop", channel->pressure_drop()},
                          {"pressure_drop_caps", channel->pressure_drop_from_caps()},
                          {"wall_gap", channel->wall_gap()},
                          {"wall_gmres_iterations", channel->wall_gmres_iterations()},
                          {"closest_approach", wall_gap->summary()}};
  }
  if (far_check->enabled()) summary[far_check->name()] = far_check->summary(dyn->single_layer());
  if (dl_far_check->enabled())
    summary[dl_far_check->name()] = dl_far_check->summary(dyn->viscosity_ratio_solver()->double_layer());
  summary["peak_rss_mb"] = peak_rss_mb();
  summary["run_id"] = run_id;
  summary["mesh_hash"] = mesh_hash;
  return summary;
}

void Simulation::Impl::log_finish(const nlohmann::json& timing) const {
  spdlog::info("phase                       seconds   share  cpu/wall ({} threads)", threads);
  const double total = timing["total_seconds"].get<double>();
  for (const auto& [k, v] : timing["phases"].items()) {
    const double wall = v.get<double>(), cpu = timing["cpu_seconds"][k].get<double>();
    spdlog::info("  {:<26}{:>8.2f}  {:>5.1f}%  {:>8.2f}", k, wall, total > 0 ? 100 * wall / total : 0, wall > 0 ? cpu / wall : 0);
  }
  std::string per_kind;  // only where there is a rotation solve (GSMB)
  if (timing["iterations"]["newton"].get<long>() > 0) {
    for (const auto& [k, c] : timing["iterations"]["by_evaluation"].items()) {
      const double e = c["evaluations"].get<double>();
      per_kind += fmt::format("  {} {:.2f} / {:.1f} ({:.0f})", k, c["newton"].get<double>() / e,
                              c["rotation_cg"].get<double>() / e, e);
    }
  }
  if (!per_kind.empty()) spdlog::info("rotation Newton / CG per evaluation (evaluations):{}", per_kind);
  std::string gmres_per_kind;  // λ ≠ 1 (outputs left out: their count includes wall-only solves)
  for (const auto& [k, c] : timing["iterations"]["by_evaluation"].items())
    if (c.contains("gmres") && k != "output")
      gmres_per_kind += fmt::format("  {} {:.2f}", k, c["gmres"].get<double>() / c["evaluations"].get<double>());
  if (!gmres_per_kind.empty()) spdlog::info("GMRES iterations per evaluation:{}", gmres_per_kind);
  for (int k = 0; k < capsules(); ++k) {
    const ShapeDiagnostics& s = watch[static_cast<std::size_t>(k)].last_shape;
    spdlog::info("{}D12 {:.4f}  D13 {:.4f}  D23 {:.4f}  L {:.3f} {:.3f} {:.3f}  Le {:.3f} {:.3f} {:.3f}",
                 capsules() == 1 ? std::string() : fmt::format("capsule {}: ", k + 1), s.D.D12, s.D.D13, s.D.D23, s.L[0],
                 s.L[1], s.L[2], s.Le[0], s.Le[1], s.Le[2]);
  }
}

}  // namespace capsflow
