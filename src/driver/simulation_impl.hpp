#pragma once
// The parts of a Simulation (driver/simulation.hpp) and who does what with them; private to
// src/driver/. Set-up: run_setup.cpp. The step: run.cpp. Outputs and checkpoints: run_output.cpp.
// Progress line, timing table, summary.json: run_report.cpp. RunState: run_state.cpp.
#include <atomic>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "capsflow/core/driver/far_field_watch.hpp"
#include "capsflow/core/driver/restart_rules.hpp"
#include "capsflow/core/driver/simulation.hpp"
#include "capsflow/core/driver/stop_reason.hpp"
#include "capsflow/core/geometry/flow_plane.hpp"
#include "capsflow/core/geometry/shape_diagnostics.hpp"
#include "capsflow/core/health/health_monitor.hpp"
#include "capsflow/core/health/instability_watch.hpp"
#include "capsflow/core/health/steady_state.hpp"
#include "capsflow/core/io/checkpoint.hpp"
#include "capsflow/core/io/folder_lock.hpp"
#include "capsflow/core/io/results_writer.hpp"
#include "capsflow/core/phase_times.hpp"
#include "capsflow/core/geometry/surface_set.hpp"
#include "capsflow/core/health/surface_gap_watch.hpp"
#include "capsflow/core/health/wall_gap_watch.hpp"
#include "capsflow/core/rhs/capsules_dynamics.hpp"
#include "capsflow/core/rhs/channel_dynamics.hpp"
#include "capsflow/core/rhs/suspension_dynamics.hpp"
#include "capsflow/core/stepping/time_plan.hpp"
#include "capsflow/core/stepping/time_stepper.hpp"

namespace capsflow {

// The part of a run that was discarded when the wall creased at the mesh scale and the plan started
// the run again from t = 0 (CreaseAction::Rewind, crease_rule.cpp).
struct AutoToleranceRewind {
  double t = 0;            // γ̇t at which the creases were seen; the restarted run is tight until here
  long steps = 0;          // accepted steps of the discarded part
  long evaluations = 0;    // its right-hand-side evaluations (counted in the run's total)
  double seconds = 0;      // its wall time (counted in the run's total)
  nlohmann::json to_json() const;
  static AutoToleranceRewind from_json(const nlohmann::json& j);
};

// Everything that evolves, and what a checkpoint must carry to continue bit for bit (with the
// scheme's own state, TimeStepper::save).
struct RunState {
  Points x;
  double t = 0, dt = 0;
  long step = 0;
  long next_output = 1;      // index k of the next output time k·every
  long next_checkpoint = 1;  // index of the next periodic checkpoint
  double volume0 = 0, area0 = 0;
  double wall_seconds_before = 0;  // wall time of earlier (restarted) segments
  long rejected_steps = 0;         // steps retried with a smaller step (all segments)
  long rhs_evaluations = 0;        // right-hand-side evaluations of earlier segments
  double gmres_per_eval_max = 0;   // λ ≠ 1: the largest gmres_per_eval of a timeseries row (all segments)
  Vec3 centroid_frame = Vec3::Zero();  // the centroid of x, in the frame the shape is computed in
  Vec3 centroid_lab = Vec3::Zero();    // the same point in the lab frame (geometry/lab_centroid.hpp)
  // Where the run stands with respect to the creases (the time plan's CreaseAction):
  bool tolerance_tightened = false;  // Rewind: the creases were seen (the tight tolerance, until rewind->t)
  std::optional<AutoToleranceRewind> rewind;  // Rewind: the discarded part, if any
  std::optional<double> creases_seen_at;      // Loosen: γ̇t where the run saw the creases (looser after)
  CreaseHistory creases() const;
  nlohmann::json extra() const;    // the checkpoint's "extra" entries of the run itself
  void set_extra(const nlohmann::json& e);
};

// One capsule's observers: its shape at the last output, its health, its membrane's rotation.
struct CapsuleWatch {
  std::unique_ptr<HealthMonitor> health;
  std::unique_ptr<TankTreadingMeter> tank_treading;
  ShapeDiagnostics last_shape;
  InPlaneShape last_plane_shape;
  double last_tank_treading = std::numeric_limits<double>::quiet_NaN();
  Vec3 last_velocity = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());  // lab; NaN: not evaluated
  double volume0 = 0;  // of its reference
};

struct Simulation::Impl {
  Impl(RunOptions o, const std::atomic<int>& stop_request) : opt(std::move(o)), stop_request(stop_request) {}

  // run_setup.cpp
  void set_up();
  void set_up_folder(io::CheckpointState& ck);         // takes the folder lock, then:
  void set_up_restart_folder(io::CheckpointState& ck);  // the restart plan, the checkpoint's mesh
  void set_up_new_folder();
  // Throws SetUpInterrupted when a stop was requested, after undoing what the set-up did to the
  // folder (the lock; a folder it created). Called between the parts of the set-up.
  void stop_set_up_if_requested();
  void make_parts();          // the right-hand side, monitors and watches, fresh
  void start_at_reference();  // the state at t = 0
  void write_first_output();  // the row and checkpoint at the run's start
  void choose_time_plan(const io::CheckpointState& ck);  // a new plan, or a restart's stored one
  double tolerance_in_force() const { return plan.tolerance_in_force(st.creases(), st.t); }
  double stepper_tolerance = 0;  // the tolerance the stepper holds (error control)
  void make_stepper();  // the plan's scheme at the tolerance in force
  void restore(const io::CheckpointState& ck);
  nlohmann::json metadata() const;
  std::unique_ptr<io::ResultsWriter> new_results_writer() const;  // a fresh run.h5 of ref (each capsule its grid)
  void log_set_up() const;
  // run.cpp: the step and what it is made of
  std::optional<StopReason> step();
  std::optional<StopReason> attempt_step(StepAttempt& a);
  std::optional<StopReason> check_step(const StepAttempt& a);
  void roll_back();
  void write_due_outputs(double t_step_start);  // after a step from t_step_start to st.t
  bool checkpoint_due() const;                  // st.t is the next periodic checkpoint's time
  void advance_checkpoint_index();              // to the first checkpoint time after st.t
  void advance_centroid(double t_step_start);   // the lab centroid over the step just accepted
  Vec3 lab_centroid_at(double t, const Points& x) const;  // at an output time inside that step
  std::optional<StopReason> observe_health();
  // crease_rule.cpp: the time plan's CreaseAction once the wall creases at the mesh scale
  bool wall_creased() const;  // a wall folded at the mesh scale into creases (auto_tolerance.hpp's criterion)
  double largest_facet_angle() const;  // of every capsule's last health sample
  bool follow_crease_rule(bool health_stop);  // after an accepted step; true: the run was rewound to t = 0
  bool rewind_to_start();                     // true: rewound (false: this folder cannot, tight from here)
  void follow_tolerance_in_force();           // the stepper takes the plan's tolerance where it changes
  std::optional<StopReason> stop(StopReason r);
  // run_output.cpp
  const Points& state_velocity();
  void write_output() { write_output_at(st.t, st.x, true); }
  // One output at time t of positions x: the state's (at_state), or with dense output a state
  // interpolated inside the last step, whose wall and load are solved for it and then put back.
  void write_output_at(double t, const Points& x, bool at_state);
  void write_checkpoint(const std::filesystem::path& path);
  // A caller's checkpoint (Simulation::write_checkpoint): refuses a path that is one of this run's
  // own files or lies in a folder another run holds locked, then writes it.
  void write_caller_checkpoint(const std::filesystem::path& path);
  // run_report.cpp
  void report_progress(bool force);
  nlohmann::json timing_table() const;
  nlohmann::json summary() const;
  void log_finish(const nlohmann::json& timing) const;

  // The next time a step must land on: the next output time or t_end; with dense output
  // (TimeStepper::interpolates) the next checkpoint time or t_end.
  double t_stop() const;
  double time_to_stop() const;  // t_stop() − t, as the step control computes it
  long rhs_evaluations() const { return st.rhs_evaluations + dyn->counters().evaluations; }
  double wall_seconds() const { return st.wall_seconds_before + segment_clock.seconds(); }

  RunOptions opt;
  const std::atomic<int>& stop_request;  // Simulation::request_stop: 0 none, > 0 the signal, −1 a caller
  Scene scene;
  SurfaceMesh ref;
  std::filesystem::path folder;
  io::FolderLock folder_lock;              // one writer per run folder, held for the life of the run
  bool folder_created = false;             // the set-up created `folder` (removed again if it stops)
  RestartPlan restart;                     // restart.new_folder: a new run folder started from the checkpoint
  std::filesystem::path checkpoint_path;   // the checkpoint actually read (after a fallback: the previous one)
  std::string run_id, mesh_hash;
  int threads = 1;

  std::unique_ptr<SurfaceSet> surfaces;    // the capsules in ref: each one's rows (one: all of them)
  int capsules() const { return surfaces->size(); }
  SurfaceMesh capsule_mesh(const Points& x, int k) const;  // capsule k at the union's positions x
  // Capsule k's volume centroid in the lab frame, from the common centroid's in the lab and in the
  // frame of x: the frame moves every capsule alike.
  Vec3 capsule_centroid_lab(const Vec3& common_lab, const Vec3& common_frame, const Points& x, int k) const;
  std::unique_ptr<CapsulesDynamics> dyn;   // the right-hand side: CapsuleDynamics, or SuspensionDynamics
  SuspensionDynamics* suspension = nullptr;  // dyn, when there are several capsules
  ChannelDynamics* channel = nullptr;        // dyn, in a channel
  // A straight channel's frame moves with the capsule (a constriction's is the lab's).
  bool comoving_channel() const { return channel && channel->channel().geometry.straight(); }
  TimePlan plan;                           // how the run is stepped (stepping/time_plan.hpp)
  bool plan_from_checkpoint = false;       // a restart kept its checkpoint's plan
  std::unique_ptr<TimeStepper> stepper;    // the plan's scheme
  std::unique_ptr<io::ResultsWriter> out;
  std::unique_ptr<SteadyStateDetector> steady;
  std::vector<CapsuleWatch> watch;         // one per capsule
  std::unique_ptr<SurfaceGapWatch> gap;    // several capsules: the closest approach
  std::unique_ptr<WallGapWatch> wall_gap;  // in a channel: the capsule's closest approach to the wall
  InstabilityWatch instability;            // geometric growth of the volume drift: a blow-up at its start
  std::unique_ptr<FarFieldWatch> far_check;  // fluid.verify_every: the single layer's far field
  std::unique_ptr<FarFieldWatch> dl_far_check;  // ... and the double layer's (λ ≠ 1; disabled otherwise)
  void update_far_checks();                   // both watches, at the state's time st.t
  RhsCounters effort_mark;                 // counters at the last health observation

  RunState st;
  std::optional<StopReason> stopped;
  Stopwatch segment_clock, report_clock;
  long steps_this_segment = 0;
  int consecutive_rejections = 0;
  int consecutive_solver_failures = 0;  // retried in shorter steps (run.cpp)
  double t_segment_start = 0;
  double last_output_t = -1;
  // The flow-plane observables of every row (geometry/flow_plane.hpp): in-plane shape and the
  // membrane's rotation rate since the previous row (NaN on a segment's first row), per capsule.
  FlowPlane plane;
  void measure_shapes(const Points& x, double t);  // every watch's shape at an output of time t
  nlohmann::json capsule_summary(int k) const;     // summary.json's entry of capsule k
  Eigen::VectorXd wall_state() const;              // every capsule's wall state, concatenated
  void set_wall_state(const Eigen::VectorXd& s);
  RhsCounters output_mark;  // the right-hand side's counters at the last row (gmres_per_eval)
  Points x_prev, v_out, x_between;  // x_between: an interpolated output state
  double centroid_step_start = 0;    // the last accepted step's start, and its centroids there
  Vec3 centroid_frame_prev = Vec3::Zero(), centroid_lab_prev = Vec3::Zero();
  Eigen::VectorXd wall_prev;
};

}  // namespace capsflow
