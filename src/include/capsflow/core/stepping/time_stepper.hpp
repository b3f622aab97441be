#pragma once
// The seam between the run loop and a time scheme (docs/time-integration.md §5): the loop asks the
// scheme for its next step, tries it, and saves or restores the scheme's state; it never names a
// scheme. Each scheme owns its step control, its checkpoint state and whether the right-hand side
// was last evaluated at the current state.
//
// A new scheme: one file implementing TimeStepper, its enum value and name in time_scheme.hpp,
// its line in make_time_stepper (time_stepper.cpp) and, if "auto" may choose it, in the time plan.
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>
#include <nlohmann/json_fwd.hpp>

#include "capsflow/core/geometry/surface_set.hpp"
#include "capsflow/core/rhs/right_hand_side.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

struct Scene;
struct TimePlan;

// Where the next step starts and how far it may go.
struct StepRequest {
  double t = 0;        // current time
  double to_stop = 0;  // time left to the next stop (an output time, or for a scheme with dense output
                       // a checkpoint time, or t_end, whichever comes first): never passed
  long step = 0;       // accepted steps so far (the whole run, restarts included)
};

struct StepAttempt {
  bool accepted = true;  // false: an error test failed and x is unchanged; ask for a new step
  double dt = 0;         // the step taken (or attempted); may be shorter than asked (stage cap)
  int stages = 0;        // right-hand-side stages of the step (ρ estimates not counted)
};

class TimeStepper {
 public:
  virtual ~TimeStepper() = default;

  // The step the scheme takes next from x: its own control (stability or error), landing on the
  // stop (r.to_stop ahead) instead of passing it. May evaluate f (a first step, a spectral-radius refresh).
  virtual double next_step(RightHandSide& f, const Points& x, const StepRequest& r) = 0;
  // One attempt of size dt (from next_step) from x. Accepted: x ← the new state. Rejected: x as it was.
  virtual StepAttempt attempt(RightHandSide& f, Points& x, double dt) = 0;

  // Dense output: a scheme that can give the state anywhere inside its last accepted step does not
  // have to land on output times (only on checkpoints and t_end). interpolate(θ, x) is the state at
  // t_n + θ τ, 0 < θ < 1, of the last accepted step from t_n; valid until the next attempt.
  virtual bool interpolates() const { return false; }
  virtual void interpolate(double theta, Points& x) const {
    (void)theta, (void)x;
    throw std::logic_error("TimeStepper::interpolate: this scheme has no dense output");  // callers ask interpolates()
  }

  // A scheme with error control (RKC2, ROCK4) takes tolerance `tol` from its next step on, its controller's
  // next proposal rescaled to it; false: this scheme has no tolerance (Heun, a fixed step).
  virtual bool set_tolerance(double tol) {
    (void)tol;
    return false;
  }

  // An inner solve failed inside an attempt of size dt and the driver rolled the state back: a
  // scheme with error control takes a quarter of dt next, from the same state (true); false: it
  // cannot shorten its step (Heun's is the stable one, a fixed dt is the user's).
  virtual bool shorten_after_failure(double dt) {
    (void)dt;
    return false;
  }

  // F at the current state when the scheme's last evaluation was there, so that what the
  // right-hand side holds (load, wall state) belongs to this state; nullptr otherwise.
  virtual const Points* velocity_at_state() const = 0;
  // The state, or the right-hand side's warm starts, changed outside the scheme (a step rolled
  // back, an evaluation for output): drop F(x) kept from before.
  virtual void forget_state() = 0;

  // Checkpoint: the scheme's scalars under its own keys of the checkpoint's `extra` object, its
  // vectors as one matrix. load() gets the restored state x and what an older run may have saved.
  virtual void save(nlohmann::json& extra, Eigen::MatrixXd& matrix) const = 0;
  virtual void load(const nlohmann::json& extra, const Eigen::MatrixXd& matrix, const Points& x) = 0;

  // Reports: the status-line fragment ("heun", "rkc s  12", "rock4 s  12"); summary.json's scheme-specific keys
  // at the final state x after `steps` accepted steps (docs/scene-and-output.md §3.5).
  virtual std::string status() const = 0;
  virtual void summarize(nlohmann::json& summary, const Points& x, long steps) const = 0;
};

// The plan's scheme (stepping/time_plan.hpp) for a run from state x, at `tolerance` (the plan's
// tolerance in force there; unused without error control). volume0: the enclosed volume that a
// stabilised scheme projects onto with fluid.volume_correction (docs/time-integration.md §5.6).
std::unique_ptr<TimeStepper> make_time_stepper(const Scene& scene, const TimePlan& plan, double tolerance,
                                               const Triangles& triangles, double volume0, const Points& x);
// Several capsules (rhs/suspension_dynamics.hpp), one scene for all: the same scheme on the rows of
// the union of `capsules`, its stiffness from the union's shortest edge (the stiffest capsule's),
// each capsule's volume projected onto its own volumes0[k].
std::unique_ptr<TimeStepper> make_time_stepper(const Scene& scene, const TimePlan& plan, double tolerance,
                                               const SurfaceSet& capsules, std::vector<double> volumes0, const Points& x);

}  // namespace capsflow
