#include "capsflow/core/driver/run.hpp"

#include <omp.h>
#include <spdlog/spdlog.h>

#include <sys/resource.h>

#include <atomic>
#include <csignal>
#include <limits>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "capsflow/core/driver/far_field_watch.hpp"
#include "capsflow/core/driver/restart_rules.hpp"
#include "capsflow/core/driver/time_grid.hpp"
#include "capsflow/core/rhs/capsule_dynamics.hpp"
#include "capsflow/core/health/health_monitor.hpp"
#include "capsflow/core/stepping/heun.hpp"
#include "capsflow/core/health/instability_watch.hpp"
#include "capsflow/core/stepping/rkc.hpp"
#include "capsflow/core/health/run_health.hpp"
#include "capsflow/core/health/steady_state.hpp"
#include "capsflow/core/rhs/volume_constraint.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/geometry/shape_diagnostics.hpp"
#include "capsflow/core/geometry/taylor_deformation.hpp"
#include "capsflow/core/io/checkpoint.hpp"
#include "capsflow/core/io/h5.hpp"
#include "capsflow/core/io/output_folder.hpp"
#include "capsflow/core/io/results_writer.hpp"
#include "capsflow/core/io/run_identity.hpp"
#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/geometry/profiles.hpp"
#include "capsflow/core/stepping/stability.hpp"
#include "capsflow/core/io/version.hpp"

namespace capsflow {

namespace {

std::atomic<int> g_signal{0};
extern "C" void on_signal(int sig) {
  g_signal = sig;
  std::signal(sig, SIG_DFL);  // a second Ctrl-C stops at once, without the checkpoint
}

std::array<double, 3> taylor_of(const SurfaceMesh& m) {
  const TaylorDeformation d = taylor_deformation(inertia_ellipsoid(m));
  return {d.D12, d.D13, d.D23};
}

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

// Everything that evolves, and what a checkpoint must carry to continue bit for bit.
struct RunState {
  Points x;
  double t = 0, dt = 0;
  long step = 0;
  long next_output = 1;      // index k of the next output time k·every
  long next_checkpoint = 1;  // index of the next periodic checkpoint
  double volume0 = 0, area0 = 0;
  double wall_seconds_before = 0;  // wall time of earlier (restarted) segments
  long rejected_steps = 0;         // RKC steps retried with a smaller step (all segments)
  long rhs_evaluations = 0;        // right-hand-side evaluations of earlier segments
  long stages_total = 0, stages_max = 0;  // over accepted RKC steps (all segments)
  nlohmann::json extra() const {
    return {{"next_output", next_output}, {"next_checkpoint", next_checkpoint}, {"volume0", volume0},
            {"area0", area0}, {"wall_seconds", wall_seconds_before}, {"rejected_steps", rejected_steps},
            {"rhs_evaluations", rhs_evaluations}, {"stages_total", stages_total}, {"stages_max", stages_max}};
  }
  void set_extra(const nlohmann::json& e) {
    next_output = e.at("next_output");
    next_checkpoint = e.at("next_checkpoint");
    volume0 = e.at("volume0");
    area0 = e.at("area0");
    wall_seconds_before = e.at("wall_seconds");
    // Written since the RKC integrator (absent in older checkpoints: zero).
    rejected_steps = e.value("rejected_steps", 0L);
    rhs_evaluations = e.value("rhs_evaluations", 0L);
    stages_total = e.value("stages_total", 0L);
    stages_max = e.value("stages_max", 0L);
  }
};

// One attempt at a step, whichever the scheme.
struct StepOutcome {
  bool progress = true;  // false: the step would not advance t (nothing was done)
  bool accepted = true;
  double dt = 0;  // the step taken (or attempted, when rejected)
  int stages = 0;
};

class Simulation {
 public:
  Simulation(const RunOptions& opt) : opt_(opt) {}
  int run();

 private:
  void setup();
  double next_dt() const;
  double clip_to_outputs(double dt) const;
  StepOutcome advance();
  long rhs_evaluations() const { return st_.rhs_evaluations + dyn_->counters().evaluations; }
  void write_output();
  void write_checkpoint();
  void report_progress(bool force);
  nlohmann::json timing_table() const;
  void finish(const std::string& stop_reason);
  // Health monitors after an accepted step (or at the start): logs each new episode once; returns
  // the stop reason when the scene asked to stop on one of them (time.stop_on), else "".
  std::string observe_health();
  double wall_seconds() const { return st_.wall_seconds_before + segment_clock_.seconds(); }

  RunOptions opt_;
  Scene scene_;
  SurfaceMesh ref_;
  std::unique_ptr<CapsuleDynamics> dyn_;
  Heun heun_;
  // Heun's automatic step also respects the measured spectral radius: the calibrated constant of
  // stability.cpp covers a/b ≤ 1.4 and misses the stiffness of elongated shapes (a/b = 4: the
  // power iteration sees 1.35× the constant's bound at t = 0). Refreshed every kHeunRhoEvery steps.
  static constexpr long kHeunRhoEvery = 50;
  SpectralRadiusEstimator heun_power_;
  double heun_rho_ = 0;   // margin included; 0: not measured (the calibrated limit alone)
  long heun_rho_step_ = -1;  // step at which heun_rho_ was measured
  Points heun_f_;
  void refresh_heun_rho();
  std::unique_ptr<Rkc> rkc_;
  Rkc::Rhs rhs_;
  bool rhs_at_state_ = false;  // the right-hand side was last evaluated at st_.x
  Points projection_scratch_;
  std::unique_ptr<io::ResultsWriter> out_;
  std::unique_ptr<SteadyStateDetector> steady_;
  std::unique_ptr<HealthMonitor> health_;
  InstabilityWatch instability_;  // geometric growth of the volume drift: a blow-up at its start
  RhsCounters effort_mark_;  // counters at the last health observation
  std::filesystem::path folder_;
  RunState st_;
  Stopwatch segment_clock_, report_clock_;
  long steps_this_segment_ = 0;
  int consecutive_rejections_ = 0;
  double t_segment_start_ = 0;
  int last_stages_ = 0;
  // An error test failing this often in a row means the step cannot be resolved (each rejection
  // shrinks the step by at least 1.25×: 50 of them, by 1e-5 at least).
  static constexpr int kMaxConsecutiveRejections = 50;
  double last_output_t_ = -1;
  ShapeDiagnostics last_shape_;
  Points x_prev_, v_out_;
  Eigen::VectorXd wall_prev_;
  int threads_ = 1;
  std::string run_id_, mesh_hash_;
  std::unique_ptr<FarFieldWatch> far_check_;  // fluid.verify_every
  RestartPlan restart_;  // restart_.new_folder: a new run folder started from the checkpoint
  std::filesystem::path checkpoint_path_;  // the checkpoint actually read (after a fallback: the previous one)
};

void Simulation::setup() {
  if (opt_.threads > 0) omp_set_num_threads(opt_.threads);
  threads_ = omp_get_max_threads();
  io::CheckpointState ck;
  if (!opt_.restart.empty()) {
    io::LoadedCheckpoint loaded = io::load_checkpoint_for_restart(opt_.restart);
    if (!loaded.fallback_reason.empty())
      spdlog::warn("{}; continuing from the previous checkpoint {} (t = {:g})", loaded.fallback_reason, loaded.path.string(),
                   loaded.state.t);
    ck = std::move(loaded.state);
    checkpoint_path_ = loaded.path;
    restart_ = plan_restart(ck, loaded.path, opt_.restart_overrides, opt_.output_dir);  // refuses before any write
    scene_ = restart_.scene;
    folder_ = restart_.folder;
    if (restart_.new_folder) io::prepare_output_folder(folder_, false);
    else if (const auto removed = io::open_output_folder_for_restart(folder_).removed; !removed.empty())
      spdlog::info("removed {} temporaries left by killed runs (first: {})", removed.size(), removed.front().filename().string());
    ref_ = SurfaceMesh{ck.reference_positions, ck.triangles};
    run_id_ = restart_.run_id;
  } else {
    scene_ = opt_.scene;
    folder_ = opt_.output_dir;
    ref_ = make_reference_mesh(scene_.mesh);  // validates a user mesh before touching the folder
    const io::PreparedFolder prepared = io::prepare_output_folder(folder_, opt_.overwrite);
    if (!prepared.kept.empty())
      spdlog::info("output folder: kept {} entries capsflow did not write (first: {})", prepared.kept.size(),
                   prepared.kept.front().filename().string());
    run_id_ = io::new_run_id();
  }
  mesh_hash_ = io::mesh_hash(ref_.vertices, ref_.triangles);
  steady_ = std::make_unique<SteadyStateDetector>(scene_.time.steady_tol);
  dyn_ = std::make_unique<CapsuleDynamics>(scene_, ref_, threads_);
  health_ = std::make_unique<HealthMonitor>(scene_, ref_);
  instability_ = InstabilityWatch(scene_.fluid.volume_correction ? InstabilityWatch::Volume::Corrected
                                                                 : InstabilityWatch::Volume::Uncorrected);
  far_check_ = std::make_unique<FarFieldWatch>(scene_.fluid.verify_every, scene_.fluid.tolerance);
  rhs_ = [this](const Points& x, Points& v) { dyn_->velocity(x, v); };
  if (scene_.time.scheme == TimeScheme::Rkc) {
    Rkc::Options ro;
    ro.tolerance = scene_.time.tolerance;
    ro.error_control = scene_.time.dt_auto;
    // The calibrated Heun limit (real stability interval 2) gives the analytic bound used when
    // the power iteration does not converge.
    ro.analytic_rho = [this](const Points& x) {
      return 2.0 / stability_estimate(scene_, min_edge_length(SurfaceMesh{x, ref_.triangles})).limit();
    };
    // RKC's large steps add O(τ³) volume error per step that the velocity-level correction
    // cannot see: project each new state back onto the initial volume.
    if (scene_.fluid.volume_correction)
      ro.project = [this](Points& y) { project_volume(y, ref_.triangles, st_.volume0, projection_scratch_); };
    rkc_ = std::make_unique<Rkc>(ro);
  }
  if (!opt_.restart.empty()) {
    st_.x = ck.positions;
    st_.t = ck.t;
    st_.dt = ck.dt;
    st_.step = ck.step;
    dyn_->wall().set_state(ck.wall_state);
    steady_->set_history(ck.history);
    const auto e = nlohmann::json::parse(ck.extra);
    st_.set_extra(e);
    if (e.contains("far_field_check")) far_check_->set_state(e.at("far_field_check"));
    // A changed output.every or checkpoint_every counts its index from the checkpoint time.
    const Scene stored = parse_scene(ck.scene_toml, "checkpoint");
    st_.next_output = restart_index(e.at("next_output").get<std::int64_t>(), stored.output.every, scene_.output.every, st_.t);
    st_.next_checkpoint = restart_index(e.at("next_checkpoint").get<std::int64_t>(), stored.output.checkpoint_every,
                                        scene_.output.checkpoint_every, st_.t);
    if (e.contains("health")) health_->set_state(e.at("health"));
    if (!rkc_ && e.contains("heun_rho")) {
      heun_rho_ = e.at("heun_rho").at("rho");
      heun_rho_step_ = e.at("heun_rho").at("step");
      if (ck.integrator_state.rows() == st_.x.rows() && ck.integrator_state.cols() == 3) heun_power_.set_direction(ck.integrator_state);
    }
    if (rkc_ && e.contains("rkc")) {
      rkc_->set_scalar_state(e.at("rkc"));
      rkc_->set_matrix_state(ck.integrator_state);
      rhs_at_state_ = false;  // F(y_n) is restored, but the wall's last evaluation is the checkpoint's
    }
    last_output_t_ = st_.t;
  } else {
    st_.x = ref_.vertices;
    st_.volume0 = enclosed_volume(ref_);
    st_.area0 = surface_area(ref_);
    steady_->add(0.0, st_.area0, taylor_of(ref_));
  }
  nlohmann::json meta = {{"scene_toml", scene_.toml_text}, {"scene_resolved", to_json(scene_)},
                         {"command_line", opt_.command_line}, {"version", version_string()},
                         {"git_hash", git_hash()}, {"build", build_info()}, {"threads", threads_},
                         {"backend", to_string(dyn_->single_layer().backend())},
                         {"backend_reason", dyn_->single_layer().backend_reason()},
                         {"fmm_order", dyn_->single_layer().fmm_order()}};
  meta["run_id"] = run_id_;
  meta["mesh_hash"] = mesh_hash_;
  if (restart_.new_folder) {
    meta["parent_run_id"] = restart_.parent_run_id;
    meta["parent_checkpoint"] = std::filesystem::absolute(checkpoint_path_).lexically_normal().string();
    meta["t_start"] = st_.t;
  }
  out_ = opt_.restart.empty() || restart_.new_folder ? std::make_unique<io::ResultsWriter>(folder_, ref_, meta)
                              : std::make_unique<io::ResultsWriter>(io::ResultsWriter::reopen(folder_, st_.t, meta));
  spdlog::info("capsflow {} (git {}), {} threads", version_string(), git_hash(), threads_);
  spdlog::info("scene {}: {} elements, {} nodes, wall {} {}, flow {}, Ca_s = {:g}", scene_.source, ref_.num_elements(),
               ref_.num_nodes(), to_string(scene_.wall.model), shell::to_string(scene_.wall.law), to_string(scene_.flow.type),
               scene_.flow.ca_s);
  spdlog::info("boundary integral: {} ({})", to_string(dyn_->single_layer().backend()), dyn_->single_layer().backend_reason());
  if (const std::string note = unused_fmm_order_note(scene_, dyn_->single_layer().backend()); !note.empty())
    spdlog::warn("{}", note);
  spdlog::info("output: {}{}", folder_.string(), opt_.restart.empty() ? "" : fmt::format(" (restart from t = {:g})", st_.t));
  if (restart_.new_folder) spdlog::info("new run folder from checkpoint {} (earlier history stays there)", checkpoint_path_.string());
  if (const std::string note = capillary_note(scene_); !note.empty()) spdlog::info("note: {}", note);
  if (scene_.time.scheme_auto)
    spdlog::info("time scheme: {} (auto: {})", to_string(scene_.time.scheme),
                 scene_.wall.model == WallModel::Gsmb ? "error-controlled RKC for a wall with bending stiffness"
                                                      : "Heun at its stability limit for a membrane wall");
  if (!rkc_ && !scene_.time.dt_auto) {
    const double limit = stability_estimate(scene_, min_edge_length(SurfaceMesh{st_.x, ref_.triangles})).limit();
    if (scene_.time.dt > limit)
      spdlog::warn("time.dt = {:g} is {:.2g}× the stability estimate {:.3g} of this mesh and wall: Heun is expected to blow up "
                   "(use dt = \"auto\", or time.scheme = \"rkc\", whose stages follow the stiffness)",
                   scene_.time.dt, scene_.time.dt / limit, limit);
  }
}

double Simulation::next_dt() const {
  double dt = scene_.time.dt;
  if (scene_.time.dt_auto) {
    const SurfaceMesh cur{st_.x, ref_.triangles};
    const double limit = stability_estimate(scene_, min_edge_length(cur)).limit();
    // Heun's real stability interval is [−2, 0]: Δt ≤ 2/ρ.
    dt = scene_.time.dt_safety * (heun_rho_ > 0 ? std::min(limit, 2.0 / heun_rho_) : limit);
  }
  return clip_to_outputs(dt);
}

void Simulation::refresh_heun_rho() {
  dyn_->velocity(st_.x, heun_f_);
  const SpectralRadiusEstimator::Result r = heun_power_.estimate(rhs_, st_.x, heun_f_);
  heun_rho_ = r.converged ? Rkc::Options{}.rho_margin * r.sigma : 0.0;  // unconverged: the calibrated limit alone
  heun_rho_step_ = st_.step;
}

double Simulation::clip_to_outputs(double dt) const {
  // Land exactly on output times and t_end.
  const double t_out = st_.next_output * scene_.output.every;
  return std::min({dt, t_out - st_.t, scene_.time.t_end - st_.t});
}

StepOutcome Simulation::advance() {
  StepOutcome o;
  if (!rkc_) {
    if (scene_.time.dt_auto && st_.step % kHeunRhoEvery == 0 && heun_rho_step_ != st_.step) refresh_heun_rho();
    o.dt = next_dt();
    if (!(o.progress = step_makes_progress(st_.t, o.dt))) return o;
    heun_.step(*dyn_, st_.x, o.dt);
    o.stages = Heun::evaluations_per_step;
    rhs_at_state_ = false;  // Heun's last evaluation is at the predictor
    return o;
  }
  const double want = scene_.time.dt_auto ? rkc_->proposed_step(rhs_, st_.x) : scene_.time.dt;
  // Land on the next output time in equal steps rather than full steps and a sliver: a sliver
  // costs an evaluation per stage like any step and advances little.
  const double remaining = clip_to_outputs(std::numeric_limits<double>::infinity());
  // Up to 20 % above the proposal (its safety factor 0.8 leaves a factor 2 in the error).
  const double tau = want >= remaining ? remaining : remaining / std::ceil(remaining / (1.2 * want));
  o.dt = tau;
  if (!(o.progress = step_makes_progress(st_.t, tau))) return o;
  const Rkc::StepReport r = rkc_->step(rhs_, st_.x, tau);
  static const bool trace = std::getenv("CAPSFLOW_TRACE_STEPS") != nullptr;
  if (trace)
    fmt::print(stderr, "TRACE t {:.5f} tau {:.4e} s {} err {:.3f} acc {} evals {} rho {:.1f}\n", st_.t, r.tau, r.stages, r.error,
               r.accepted, r.evaluations, rkc_->spectral_radius());
  o.accepted = r.accepted;
  o.dt = r.tau;
  o.stages = r.stages;
  rhs_at_state_ = r.accepted;  // F(y_{n+1}) is the last evaluation of an accepted step
  return o;
}

void Simulation::write_output() {
  const SurfaceMesh cur{st_.x, ref_.triangles};
  last_shape_ = shape_diagnostics(cur);
  const auto& s = last_shape_;
  // Loads, energies and velocities of the output state itself, not of whatever stage the
  // integrator evaluated last: RKC's last evaluation is at the new state; otherwise evaluate.
  if (rhs_at_state_ && rkc_ && rkc_->has_velocity()) {
    v_out_ = rkc_->velocity();
  } else {
    dyn_->velocity(st_.x, v_out_);
    rhs_at_state_ = true;
    if (rkc_) rkc_->forget_velocity();  // the warm start moved: recompute F(y_n) (restart-safe)
  }
  far_check_->update(dyn_->single_layer(), st_.t);
  const shell::WallEnergies en = dyn_->wall().energies(st_.x);
  io::NamedFields fields;
  if (scene_.wants_field(OutputField::Velocity)) fields.emplace_back("velocity", v_out_);
  if (scene_.wants_field(OutputField::Load)) fields.emplace_back("load", dyn_->load());
  if (scene_.wants_field(OutputField::Energy)) {
    Eigen::VectorXd Em, Eb, Esh;
    dyn_->wall().nodal_energy_maps(st_.x, Em, Eb, Esh);
    fields.emplace_back("E_membrane", Em);
    fields.emplace_back("E_bending", Eb);
    fields.emplace_back("E_shear", Esh);
  }
  out_->write_step(st_.t, st_.x, fields);
  {  // profiles in the three coordinate planes through the volume centroid
    io::h5::File f = io::h5::File::open(folder_ / io::kRunH5, io::h5::File::Mode::read_write, true);
    // Kept beside /steps (whose groups hold nodal fields only): /profiles/<k>/<plane>/{points, offsets}.
    const std::string name = fmt::format("profiles/{:06}", out_->num_steps() - 1);
    if (f.exists(name)) f.remove(name);  // left over from a run continued by --restart
    io::h5::Group g = f.require_group(name);
    g.set_attribute("time", st_.t);
    const Vec3 c = volume_moments(cur).centroid;
    for (CoordinatePlane p : {CoordinatePlane::X1X2, CoordinatePlane::X1X3, CoordinatePlane::X2X3}) {
      const auto lines = cross_section(cur, p, c);
      long n = 0;
      for (const auto& l : lines) n += static_cast<long>(l.points.size());
      Points pts(n, 3);
      Eigen::VectorXi offsets(static_cast<Eigen::Index>(lines.size() + 1));
      long k = 0;
      offsets[0] = 0;
      for (size_t i = 0; i < lines.size(); ++i) {
        for (const auto& pt : lines[i].points) pts.row(k++) = pt.transpose();
        offsets[static_cast<Eigen::Index>(i + 1)] = static_cast<int>(k);
      }
      io::h5::Group pg = g.require_group(to_string(p));
      pg.write_matrix("points", pts);
      pg.write_vector("offsets", offsets);
    }
    f.close();
  }
  io::CsvRow row = {{"t", st_.t}, {"step", static_cast<double>(st_.step)}, {"dt", st_.dt},
                    {"D12", s.D.D12}, {"D13", s.D.D13}, {"D23", s.D.D23},
                    {"Le1", s.Le[0]}, {"Le2", s.Le[1]}, {"Le3", s.Le[2]}, {"L1", s.L[0]}, {"L2", s.L[1]}, {"L3", s.L[2]},
                    {"area", s.area}, {"volume", s.volume}, {"volume_drift", s.volume / st_.volume0 - 1},
                    {"E_membrane", en.membrane}, {"E_bending", en.bending}, {"E_shear", en.shear},
                    {"steady_measure", steady_->measure()}, {"wall_seconds", wall_seconds()}};
  for (const auto& [name, value] : health_->columns()) row.emplace_back(name, value);
  far_check_->append_columns(row);  // fluid.verify_every > 0 only
  out_->append_row(row);
  last_output_t_ = st_.t;
}

void Simulation::write_checkpoint() {
  io::CheckpointState ck;
  ck.step = st_.step;
  ck.t = st_.t;
  ck.dt = st_.dt;
  ck.positions = st_.x;
  ck.reference_positions = ref_.vertices;
  ck.triangles = ref_.triangles;
  ck.wall_state = dyn_->wall().state();
  ck.history = steady_->history();
  ck.scene_toml = to_toml(scene_);
  ck.scene_resolved = to_json(scene_).dump();
  ck.version = fmt::format("{} ({})", version_string(), git_hash());
  RunState s = st_;
  s.wall_seconds_before = wall_seconds();
  s.rhs_evaluations = rhs_evaluations();
  nlohmann::json extra = s.extra();
  extra["health"] = health_->state();
  if (!rkc_) {
    extra["heun_rho"] = {{"rho", heun_rho_}, {"step", heun_rho_step_}};
    if (heun_power_.direction().rows() == st_.x.rows()) ck.integrator_state = heun_power_.direction();
  }
  if (far_check_->enabled()) extra["far_field_check"] = far_check_->state(dyn_->single_layer());
  if (rkc_) {
    extra["rkc"] = rkc_->scalar_state();
    ck.integrator_state = rkc_->matrix_state();
  }
  ck.extra = extra.dump();
  ck.run_id = run_id_;
  io::write_checkpoint(folder_ / io::kCheckpointFile, ck);
}

void Simulation::report_progress(bool force) {
  if (!force && report_clock_.seconds() < opt_.progress_interval) return;
  report_clock_.restart();
  const double seg = segment_clock_.seconds();
  const long evals = dyn_->counters().evaluations;
  const double per_eval = evals ? seg / static_cast<double>(evals) : 0;
  const double t_end = scene_.time.t_end;
  // ETA from the simulated time per wall second of this segment (RKC's step varies).
  const double done = st_.t - t_segment_start_;
  const double eta = done > 0 ? seg * (t_end - st_.t) / done : NAN;
  const SurfaceMesh cur{st_.x, ref_.triangles};
  const std::string scheme =
      rkc_ ? fmt::format("rkc s {:>3} rej {:>3}", last_stages_, st_.rejected_steps) : std::string("heun");
  spdlog::info("step {:>7}  t {:.4f}/{:g} ({:5.1f}%)  dt {:.2e}  {}  evals {:>7} ({:.1f} ms)  ETA {}  dV/V {:+.1e}  steady {:.1e} (tol {:.0e})  health {}",
               st_.step, st_.t, t_end, 100 * st_.t / t_end, st_.dt, scheme, rhs_evaluations(), 1e3 * per_eval, hms(eta),
               enclosed_volume(cur) / st_.volume0 - 1, steady_->measure(), scene_.time.steady_tol, health_->status());
}

nlohmann::json Simulation::timing_table() const {
  const PhaseTimes p = dyn_->times();
  const RhsCounters& n = dyn_->counters();
  const double total = wall_seconds() - st_.wall_seconds_before;
  // "other" is what the phases do not cover (the integrator's updates, diagnostics, output).
  nlohmann::json phases = nlohmann::json::object();
  double known = 0;
  for (std::size_t i = 0; i < kPhaseNames.size(); ++i) {
    const Phase ph = static_cast<Phase>(i);
    if (ph == Phase::Other) continue;
    phases[kPhaseNames[i]] = p[ph];
    known += p[ph];
  }
  phases[kPhaseNames[static_cast<std::size_t>(Phase::Other)]] = std::max(0.0, total - known);
  return {{"total_seconds", total}, {"steps", steps_this_segment_}, {"rhs_evaluations", n.evaluations},
          {"seconds_per_evaluation", n.evaluations ? total / static_cast<double>(n.evaluations) : 0},
          {"seconds_per_step", steps_this_segment_ ? total / static_cast<double>(steps_this_segment_) : 0},
          {"phases", phases},
          {"iterations", {{"newton", n.newton_iterations}, {"rotation_cg", n.cg_iterations}, {"mass_cg", n.mass_cg_iterations},
                          {"rotation_fresh_starts", n.rotation_fresh_starts}}}};
}

void Simulation::finish(const std::string& stop_reason) {
  const nlohmann::json timing = timing_table();
  out_->write_timings(timing);
  const auto& s = last_shape_;
  nlohmann::json summary = {
      {"t", st_.t}, {"steps", st_.step}, {"steady", steady_->steady()}, {"stop_reason", stop_reason},
      {"D12", s.D.D12}, {"D13", s.D.D13}, {"D23", s.D.D23},
      {"L", {s.L[0], s.L[1], s.L[2]}}, {"Le", {s.Le[0], s.Le[1], s.Le[2]}},
      {"area", s.area}, {"volume", s.volume}, {"volume_drift", s.volume / st_.volume0 - 1},
      {"wall_seconds", wall_seconds()}, {"elements", ref_.num_elements()}, {"nodes", ref_.num_nodes()},
      {"backend", to_string(dyn_->single_layer().backend())}, {"backend_reason", dyn_->single_layer().backend_reason()},
      {"fmm_order", dyn_->single_layer().fmm_order()}, {"threads", threads_},
      {"steady_measure", steady_->measure()}, {"timing", timing}, {"scene", to_json(scene_)},
      {"version", version_string()}, {"git", git_hash()},
      {"scheme", to_string(scene_.time.scheme)}, {"rhs_evaluations", rhs_evaluations()},
      {"rejected_steps", st_.rejected_steps}};
  if (!rkc_ && heun_rho_ > 0) summary["spectral_radius"] = heun_rho_;
  if (rkc_) {
    const long accepted = st_.step;  // every counted step of an RKC run is an accepted one
    summary["spectral_radius"] = rkc_->spectral_radius();
    // What the calibrated Heun constant implies at the final shape (real interval 2): the power
    // iteration is expected to see more on shapes the constant was not calibrated for.
    summary["spectral_radius_analytic"] = rkc_->options().analytic_rho(st_.x);
    summary["stages_max"] = st_.stages_max;
    summary["stages_mean"] = accepted > 0 ? static_cast<double>(st_.stages_total) / static_cast<double>(accepted) : 0.0;
    summary["spectral_radius_evaluations"] = rkc_->rho_evaluations();
  }
  summary["health"] = health_->summary();
  if (far_check_->enabled()) summary["far_field_check"] = far_check_->summary(dyn_->single_layer());
  summary["peak_rss_mb"] = peak_rss_mb();
  summary["run_id"] = run_id_;
  summary["mesh_hash"] = mesh_hash_;
  out_->write_summary(summary);
  const auto& ph = timing["phases"];
  // The reason's details (after ':') were logged when it happened; here its name is enough.
  spdlog::info("stopped: {} at t = {:g} after {} steps ({} rejected), {} right-hand-side evaluations, {:.1f} s",
               stop_reason.substr(0, stop_reason.find(':')), st_.t, st_.step, st_.rejected_steps, rhs_evaluations(), wall_seconds());
  spdlog::info("phase                       seconds   share");
  const double total = timing["total_seconds"].get<double>();
  for (const auto& [k, v] : ph.items())
    spdlog::info("  {:<26}{:>8.2f}  {:>5.1f}%", k, v.get<double>(), total > 0 ? 100 * v.get<double>() / total : 0);
  spdlog::info("D12 {:.4f}  D13 {:.4f}  D23 {:.4f}  L {:.3f} {:.3f} {:.3f}  Le {:.3f} {:.3f} {:.3f}", s.D.D12, s.D.D13, s.D.D23,
               s.L[0], s.L[1], s.L[2], s.Le[0], s.Le[1], s.Le[2]);
}

std::string Simulation::observe_health() {
  const RhsCounters& n = dyn_->counters();
  const double evals = static_cast<double>(n.evaluations - effort_mark_.evaluations);
  SolverEffort effort;
  if (evals > 0) {
    effort.newton_per_evaluation = static_cast<double>(n.newton_iterations - effort_mark_.newton_iterations) / evals;
    effort.rotation_cg_per_evaluation = static_cast<double>(n.cg_iterations - effort_mark_.cg_iterations) / evals;
    effort.mass_cg_per_evaluation = static_cast<double>(n.mass_cg_iterations - effort_mark_.mass_cg_iterations) / evals;
  }
  effort_mark_ = n;
  std::string stop;
  for (const HealthEvent& e : health_->observe(st_.t, st_.x, effort)) {
    const bool stops = std::find(scene_.time.stop_on.begin(), scene_.time.stop_on.end(), e.condition) != scene_.time.stop_on.end();
    spdlog::warn("{}: {}{}", to_string(e.condition), e.message, stops ? " — stopping (time.stop_on)" : "");
    if (stops && stop.empty()) stop = to_string(e.condition);
  }
  return stop;
}

int Simulation::run() {
  setup();
  g_signal = 0;
  auto old_int = std::signal(SIGINT, on_signal);
  auto old_term = std::signal(SIGTERM, on_signal);
  struct Restore {
    decltype(old_int) i, t;
    ~Restore() { std::signal(SIGINT, i), std::signal(SIGTERM, t); }
  } restore{old_int, old_term};

  if (opt_.restart.empty()) observe_health();  // the reference state: no episode can begin here
  effort_mark_ = dyn_->counters();
  if (opt_.restart.empty() || restart_.new_folder) write_output();
  else last_shape_ = shape_diagnostics(SurfaceMesh{st_.x, ref_.triangles});
  t_segment_start_ = st_.t;
  std::string stop = "t_end";
  while (!time_reached(st_.t, scene_.time.t_end, st_.dt)) {
    if (g_signal) {
      spdlog::warn("signal {} received: writing a checkpoint and stopping", static_cast<int>(g_signal));
      stop = "interrupted";
      break;
    }
    const double t_out = st_.next_output * scene_.output.every;
    x_prev_ = st_.x;
    wall_prev_ = dyn_->wall().state();  // to roll back a blown-up step
    auto roll_back = [this] {
      st_.x = x_prev_;
      dyn_->wall().set_state(wall_prev_);
      if (rkc_) rkc_->forget_velocity();  // F(y_n) may belong to the discarded state
      rhs_at_state_ = false;
    };
    StepOutcome o;
    try {
      o = advance();
      far_check_->update(dyn_->single_layer(), st_.t);
    } catch (const SolverFailure& e) {
      stop = fmt::format("solver_failure: {} at t = {:g}", e.what(), st_.t);
      spdlog::error("{}; keeping the last healthy state", stop);
      roll_back();
      break;
    }
    if (!o.progress) {
      spdlog::error("no progress at step {} (t = {:g}): the time step {:g} does not advance t; stopping", st_.step + 1, st_.t,
                    o.dt);
      stop = "no_progress";
      break;
    }
    if (!o.accepted) {
      // RKC's error test failed: the state is unchanged; retry with the controller's smaller step.
      ++st_.rejected_steps;
      if (++consecutive_rejections_ > kMaxConsecutiveRejections) {
        stop = fmt::format("no_progress: {} consecutive rejected steps at t = {:g} (last step {:.3g})",
                           consecutive_rejections_, st_.t, o.dt);
        spdlog::error("{}", stop);
        break;
      }
      continue;
    }
    consecutive_rejections_ = 0;
    st_.dt = o.dt;
    if (rkc_) {
      st_.stages_total += o.stages;
      st_.stages_max = std::max<long>(st_.stages_max, o.stages);
      last_stages_ = o.stages;
    }
    const double max_drift = blow_up_drift(scene_.fluid.volume_correction);
    const double drift = enclosed_volume(SurfaceMesh{st_.x, ref_.triangles}) / st_.volume0 - 1;
    std::string problem = check_health(SurfaceMesh{x_prev_, ref_.triangles}, st_.x, drift, max_drift);
    if (problem.empty()) problem = instability_.observe(drift, o.dt);
    if (!problem.empty()) {
      spdlog::error("blow-up at step {} (t = {:g}, dt = {:.3g}): {}; keeping the last healthy state", st_.step + 1, st_.t + st_.dt,
                    st_.dt, problem);
      roll_back();
      stop = "blow_up";
      break;
    }
    st_.t = advance_time(st_.t, st_.dt, std::min(t_out, scene_.time.t_end));
    ++st_.step;
    ++steps_this_segment_;
    const SurfaceMesh now{st_.x, ref_.triangles};
    steady_->add(st_.t, surface_area(now), taylor_of(now));
    const std::string health_stop = observe_health();
    if (time_reached(st_.t, t_out, st_.dt)) {
      write_output();
      ++st_.next_output;
    }
    if (scene_.output.checkpoint_every > 0 &&
        time_reached(st_.t, static_cast<double>(st_.next_checkpoint) * scene_.output.checkpoint_every, st_.dt)) {
      write_checkpoint();
      st_.next_checkpoint = next_index_after(st_.t, scene_.output.checkpoint_every, st_.next_checkpoint, st_.dt);
    }
    report_progress(false);
    if (!health_stop.empty()) {
      stop = health_stop;
      break;
    }
    if (scene_.time.stop_at_steady && steady_->steady()) {
      stop = "steady";
      break;
    }
  }
  if (last_output_t_ != st_.t) write_output();
  write_checkpoint();
  report_progress(true);
  finish(stop);
  if (stop == "blow_up" || stop.rfind("solver_failure", 0) == 0 || stop.rfind("no_progress", 0) == 0) return 3;
  for (const auto& [c, name] : kHealthConditionNames)
    if (stop == name) return 3;  // a time.stop_on condition: the state after it is known to be wrong
  if (stop == "interrupted") return 130;
  return 0;
}

}  // namespace

int run_simulation(const RunOptions& options) {
  Simulation sim(options);
  return sim.run();
}

}  // namespace capsflow
