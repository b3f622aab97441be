// The run loop: Simulation's public face, the step and what it is made of, and run_simulation
// (the loop with SIGINT/SIGTERM). Set-up, outputs and reports live beside it (simulation_impl.hpp).
#include "capsflow/core/driver/run.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <csignal>
#include <fmt/core.h>

#include "capsflow/core/driver/simulation.hpp"
#include "capsflow/core/driver/time_grid.hpp"
#include "capsflow/core/geometry/lab_centroid.hpp"
#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/geometry/taylor_deformation.hpp"
#include "capsflow/core/health/run_health.hpp"
#include "capsflow/core/io/checkpoint.hpp"
#include "simulation_impl.hpp"

namespace capsflow {

namespace {
// An error test failing this often in a row means the step cannot be resolved (each rejection
// shrinks the step by at least 1.25×: 50 of them, by 1e-5 at least).
constexpr int kMaxConsecutiveRejections = 50;
// A stage whose inner solve fails is retried in a step a quarter as long (schemes with error
// control): a stage far from the last state can defeat the solve's warm start where a nearer one
// does not. Three in a row (a step 64× shorter) and the failure stands.
constexpr int kMaxRetriesAfterSolverFailure = 3;
}  // namespace

// One accepted step: what a step does, in order.
std::optional<StopReason> Simulation::Impl::step() {
  if (stopped) return stopped;
  StepAttempt a;
  do {  // attempts until one is accepted
    if (time_reached(st.t, scene.time.t_end, st.dt)) return stop(StopReason(StopKind::TEnd));
    if (const int request = stop_request.load()) {
      spdlog::warn("{}: writing a checkpoint and stopping",
                   request > 0 ? fmt::format("signal {} received", request) : std::string("stop requested"));
      return stop(StopReason(StopKind::Interrupted));
    }
    if (auto failed = attempt_step(a)) return failed;
  } while (!a.accepted);
  consecutive_rejections = 0;
  consecutive_solver_failures = 0;
  const double t_step_start = st.t;
  st.dt = a.dt;
  if (auto blow_up = check_step(a)) return blow_up;
  st.t = advance_time(st.t, st.dt, t_stop());
  advance_centroid(t_step_start);
  ++st.step;
  ++steps_this_segment;
  const SurfaceMesh now{st.x, ref.triangles};
  steady->add(st.t, surface_area(now), inertia_ellipsoid(now));
  const std::optional<StopReason> health_stop = observe_health();
  // The step is accepted and its state healthy; an inner solve may still fail where the outputs it
  // passed are evaluated (an interpolated state) or where a rewind starts again: the run stops there,
  // with the rows written so far, a checkpoint of the state and its summary (finish).
  try {
    if (follow_crease_rule(health_stop.has_value())) return std::nullopt;  // rewound to t = 0
    write_due_outputs(t_step_start);
  } catch (const SolverFailure& e) {
    const StopReason r(StopKind::SolverFailure, fmt::format("{} at an output of the step to t = {:g}", e.what(), st.t));
    spdlog::error("{}; keeping the last healthy state", r.to_string());
    return stop(r);
  }
  report_progress(false);
  if (health_stop) return stop(*health_stop);
  if (channel && channel->reached_outlet(st.x)) {
    spdlog::info("the capsule's front reached x1 = {:.4g}, within {} channel radii of the outlet cap at {:.4g}: stopping",
                 st.x.col(0).maxCoeff(), ChannelDynamics::kOutletStopClearance, 0.5 * channel->channel().geometry.length);
    return stop(StopReason(StopKind::Outlet));
  }
  if (scene.time.stop_at_steady && steady->steady()) return stop(StopReason(StopKind::Steady));
  if (time_reached(st.t, scene.time.t_end, st.dt)) return stop(StopReason(StopKind::TEnd));
  return std::nullopt;
}

// The scheme's next step from the current state, tried (a rejected one is counted); the stop
// reason when it cannot be taken: an inner solve failed, or it would not advance t, or too many
// were rejected in a row.
std::optional<StopReason> Simulation::Impl::attempt_step(StepAttempt& a) {
  x_prev = st.x;
  wall_prev = wall_state();  // to roll back a blown-up step
  double dt = 0;
  try {
    dt = stepper->next_step(*dyn, st.x, {st.t, time_to_stop(), st.step});
    if (step_makes_progress(st.t, dt)) a = stepper->attempt(*dyn, st.x, dt);
    update_far_checks();
  } catch (const SolverFailure& e) {
    roll_back();
    if (dt > 0 && ++consecutive_solver_failures <= kMaxRetriesAfterSolverFailure && stepper->shorten_after_failure(dt)) {
      spdlog::warn("{} at t = {:g} in a step of {:.3g}: the step is rejected and tried again a quarter as long", e.what(), st.t, dt);
      ++st.rejected_steps;
      a = StepAttempt{false, dt, 0};
      return std::nullopt;
    }
    const StopReason r(StopKind::SolverFailure, fmt::format("{} at t = {:g}", e.what(), st.t));
    spdlog::error("{}; keeping the last healthy state", r.to_string());
    return stop(r);
  }
  if (!step_makes_progress(st.t, dt)) {
    spdlog::error("no progress at step {} (t = {:g}): the time step {:g} does not advance t; stopping", st.step + 1, st.t, dt);
    return stop(StopReason(StopKind::NoProgress));
  }
  spdlog::trace("t {:.5f}: step {:.4e} {} ({})", st.t, a.dt, a.accepted ? "accepted" : "rejected", stepper->status());
  if (a.accepted) return std::nullopt;
  // The error test failed: the state is unchanged; the scheme retries with a smaller step.
  ++st.rejected_steps;
  if (++consecutive_rejections > kMaxConsecutiveRejections) {
    const StopReason r(StopKind::NoProgress, fmt::format("{} consecutive rejected steps at t = {:g} (last step {:.3g})",
                                                         consecutive_rejections, st.t, a.dt));
    spdlog::error("{}", r.to_string());
    return stop(r);
  }
  return std::nullopt;
}

// Blow-up checks of an accepted step (health/run_health.hpp, instability_watch.hpp): a failing
// step is rolled back and stops the run.
std::optional<StopReason> Simulation::Impl::check_step(const StepAttempt& a) {
  const double drift = enclosed_volume(SurfaceMesh{st.x, ref.triangles}) / st.volume0 - 1;
  std::string problem = check_health(SurfaceMesh{x_prev, ref.triangles}, st.x, drift, blow_up_drift(scene.fluid.volume_correction));
  if (problem.empty()) problem = instability.observe(drift, a.dt);
  if (problem.empty()) return std::nullopt;
  spdlog::error("blow-up at step {} (t = {:g}, dt = {:.3g}): {}; keeping the last healthy state", st.step + 1, st.t + st.dt, st.dt,
                problem);
  roll_back();
  return stop(StopReason(StopKind::BlowUp));
}

void Simulation::Impl::roll_back() {
  st.x = x_prev;
  set_wall_state(wall_prev);
  stepper->forget_state();  // F(x) may belong to the discarded state
}

void Simulation::Impl::write_due_outputs(double t_step_start) {
  // Dense output: the output times the step passed, from its interpolant (none where it landed).
  if (stepper->interpolates()) {
    for (double t_out = static_cast<double>(st.next_output) * scene.output.every;
         scene.output.every > 0 && !time_reached(t_out, st.t, st.dt);  // before the step's end (else: below)
         t_out = static_cast<double>(st.next_output) * scene.output.every) {
      stepper->interpolate((t_out - t_step_start) / st.dt, x_between);
      write_output_at(t_out, x_between, false);
      ++st.next_output;
    }
  }
  if (time_reached(st.t, static_cast<double>(st.next_output) * scene.output.every, st.dt)) {
    write_output();
    ++st.next_output;
  }
  if (checkpoint_due()) {
    // The index first: the checkpoint must name the next checkpoint time, not its own — error-controlled steps
    // stop at checkpoint times, and a restart from one naming itself would have no time left to step.
    advance_checkpoint_index();
    write_checkpoint(folder / io::kCheckpointFile);
  }
}

void Simulation::Impl::advance_centroid(double t_step_start) {
  centroid_step_start = t_step_start;
  centroid_frame_prev = st.centroid_frame;
  centroid_lab_prev = st.centroid_lab;
  st.centroid_frame = volume_moments(st.x, ref.triangles).centroid;
  st.centroid_lab = advance_lab_centroid(scene.flow.gradient, st.t - t_step_start, centroid_lab_prev,
                                         st.centroid_frame - centroid_frame_prev);
  // In a straight channel the frame moves with the capsule along x1 (rhs/channel_dynamics.hpp): the
  // step's last evaluation's axial velocity carries the lab centroid (first order in the step where U
  // changes). A constriction's frame is the lab's.
  if (comoving_channel()) st.centroid_lab.x() += channel->axial_velocity() * (st.t - t_step_start);
}

Vec3 Simulation::Impl::lab_centroid_at(double t, const Points& x) const {
  if (t == st.t) return st.centroid_lab;
  Vec3 c = advance_lab_centroid(scene.flow.gradient, t - centroid_step_start, centroid_lab_prev,
                                volume_moments(x, ref.triangles).centroid - centroid_frame_prev);
  if (comoving_channel()) c.x() += channel->axial_velocity() * (t - centroid_step_start);
  return c;
}

bool Simulation::Impl::checkpoint_due() const {
  return scene.output.checkpoint_every > 0 &&
         time_reached(st.t, static_cast<double>(st.next_checkpoint) * scene.output.checkpoint_every, st.dt);
}

void Simulation::Impl::advance_checkpoint_index() {
  st.next_checkpoint = next_index_after(st.t, scene.output.checkpoint_every, st.next_checkpoint, st.dt);
}

// Health monitors after an accepted step (or at the start): logs each new episode once; the stop
// reason when the scene asked to stop on one of them (time.stop_on).
std::optional<StopReason> Simulation::Impl::observe_health() {
  const RhsCounters& n = dyn->counters();
  const double evals = static_cast<double>(n.evaluations - effort_mark.evaluations);
  SolverEffort effort;
  if (evals > 0) {
    effort.newton_per_evaluation = static_cast<double>(n.newton_iterations - effort_mark.newton_iterations) / evals;
    effort.rotation_cg_per_evaluation = static_cast<double>(n.cg_iterations - effort_mark.cg_iterations) / evals;
    effort.mass_cg_per_evaluation = static_cast<double>(n.mass_cg_iterations - effort_mark.mass_cg_iterations) / evals;
  }
  effort_mark = n;
  std::optional<StopReason> stop_on;
  const auto report = [&](const HealthEvent& e, const std::string& whose) {
    const bool stops = std::find(scene.time.stop_on.begin(), scene.time.stop_on.end(), e.condition) != scene.time.stop_on.end();
    spdlog::warn("{}: {}{}{}", to_string(e.condition), whose, e.message, stops ? " — stopping (time.stop_on)" : "");
    if (stops && !stop_on) stop_on = StopReason::health(e.condition);
  };
  if (capsules() == 1) {
    for (const HealthEvent& e : watch[0].health->observe(st.t, st.x, effort)) report(e, "");
    if (wall_gap)
      if (const std::optional<HealthEvent> e = wall_gap->observe(st.t, channel->wall_gap())) report(*e, "");
  } else {
    // The counters sum every capsule's inner solves: each capsule is given their mean.
    const double share = 1.0 / capsules();
    effort.newton_per_evaluation *= share;
    effort.rotation_cg_per_evaluation *= share;
    effort.mass_cg_per_evaluation *= share;
    for (int k = 0; k < capsules(); ++k) {
      const SurfacePart& p = surfaces->part(k);
      for (const HealthEvent& e : watch[static_cast<std::size_t>(k)].health->observe(st.t, st.x.middleRows(p.node_begin, p.nodes), effort))
        report(e, fmt::format("capsule {}: ", k + 1));
    }
    if (const std::optional<HealthEvent> e = gap->observe(st.t, suspension->gaps_at(st.x).closest())) report(*e, "");
  }
  return stop_on;
}

std::optional<StopReason> Simulation::Impl::stop(StopReason r) {
  stopped = std::move(r);
  return stopped;
}

double Simulation::Impl::t_stop() const {
  if (stepper->interpolates())
    return scene.output.checkpoint_every > 0
               ? std::min(static_cast<double>(st.next_checkpoint) * scene.output.checkpoint_every, scene.time.t_end)
               : scene.time.t_end;
  return std::min(static_cast<double>(st.next_output) * scene.output.every, scene.time.t_end);
}

// Each bound minus t in one expression, as the step control has always computed it: the compiler
// may fuse k·every − t into one rounding (FMA), and results are compared bit for bit across versions.
double Simulation::Impl::time_to_stop() const {
  if (stepper->interpolates())
    return scene.output.checkpoint_every > 0
               ? std::min(static_cast<double>(st.next_checkpoint) * scene.output.checkpoint_every - st.t,
                          scene.time.t_end - st.t)
               : scene.time.t_end - st.t;
  return std::min(static_cast<double>(st.next_output) * scene.output.every - st.t, scene.time.t_end - st.t);
}

Simulation::Simulation(RunOptions options) : impl_(std::make_unique<Impl>(std::move(options), stop_request_)) {}
Simulation::~Simulation() = default;

void Simulation::set_up() { impl_->set_up(); }
std::optional<StopReason> Simulation::step() { return impl_->step(); }
double Simulation::t() const { return impl_->st.t; }
double Simulation::dt() const { return impl_->st.dt; }
long Simulation::steps() const { return impl_->st.step; }
long Simulation::rhs_evaluations() const { return impl_->rhs_evaluations(); }
const Points& Simulation::positions() const { return impl_->st.x; }
const SurfaceMesh& Simulation::reference() const { return impl_->ref; }
const std::filesystem::path& Simulation::folder() const { return impl_->folder; }
const Points& Simulation::load() const { return impl_->dyn->load(); }
const Points& Simulation::velocity() { return impl_->state_velocity(); }
const HealthMonitor& Simulation::health() const { return *impl_->watch.at(0).health; }
std::optional<StopReason> Simulation::stop_reason() const { return impl_->stopped; }
void Simulation::write_checkpoint(const std::filesystem::path& path) { impl_->write_caller_checkpoint(path); }

int Simulation::finish() {
  Impl& s = *impl_;
  s.folder_lock.check_held();  // before the last writes (they check again, each)
  const StopReason reason = s.stopped.value_or(StopReason(StopKind::TEnd));
  if (s.last_output_t != s.st.t) {
    try {
      s.write_output();
    } catch (const SolverFailure& e) {  // the state's own evaluation failed (again: the stop's cause); no row
      spdlog::error("no output row at t = {:g}: {}", s.st.t, e.what());
    }
  }
  s.write_checkpoint(s.folder / io::kCheckpointFile);
  s.report_progress(true);
  const nlohmann::json timing = s.timing_table();
  s.out->write_timings(timing);
  nlohmann::json summary = s.summary();
  summary["stop_reason"] = reason.to_string();
  summary["timing"] = timing;
  s.out->write_summary(summary);
  // The reason's details were logged when it happened; here its name is enough.
  spdlog::info("stopped: {} at t = {:g} after {} steps ({} rejected), {} right-hand-side evaluations, {:.1f} s", reason.name(), s.st.t,
               s.st.step, s.st.rejected_steps, s.rhs_evaluations(), s.wall_seconds());
  s.log_finish(timing);
  // The folder is complete: another writer may continue it while this object lives on (a
  // binding's Simulation is still read after finish()).
  s.folder_lock.release();
  return reason.exit_code();
}

int Simulation::run() {
  set_up();
  while (!step()) {
  }
  return finish();
}

namespace {
// SIGINT/SIGTERM → the running simulation's stop request. A second signal stops at once, without
// the checkpoint (the default action is restored by the first).
std::atomic<Simulation*> g_running{nullptr};
extern "C" void on_signal(int sig) {
  if (Simulation* s = g_running.load()) s->request_stop(sig);
  std::signal(sig, SIG_DFL);
}
}  // namespace

int run_simulation(const RunOptions& options) {
  Simulation sim(options);
  // The handlers come before the set-up, which takes minutes on a fine mesh: a signal during it
  // (also one the parent shell would have had ignored) stops the run as interrupted, not at once
  // halfway through writing the folder, and is not lost.
  g_running = &sim;
  auto old_int = std::signal(SIGINT, on_signal);
  auto old_term = std::signal(SIGTERM, on_signal);
  struct Restore {
    decltype(old_int) i, t;
    ~Restore() {
      g_running = nullptr;
      std::signal(SIGINT, i), std::signal(SIGTERM, t);
    }
  } restore{old_int, old_term};
  try {
    sim.set_up();
  } catch (const SetUpInterrupted& e) {
    spdlog::warn("{}", e.what());
    return StopReason(StopKind::Interrupted).exit_code();
  }
  while (!sim.step()) {
  }
  return sim.finish();
}

}  // namespace capsflow
