#pragma once
// Time bookkeeping of the run loop (docs/time-integration.md §5.5, docs/scene-and-output.md §2.7):
// landing on output times and t_end, when an output or checkpoint time is reached, the next index
// of a periodic event, and whether a step makes progress at all.
//
// Tolerances are relative to the step (and a few ulps of t), never to t_end: with 1e-12·t_end,
// t_end = 1e10 snapped times by 0.01 and t_end = 1e308 made every step an output and the
// checkpoint-index loop endless.
#include <cstdint>

namespace capsflow {

// How close (absolute) two times must be to count as equal after a step of size dt at time t:
// 1e-9 of the step, plus 4 ulps of t for the rounding of t + dt itself.
double time_tolerance(double t, double dt);

// t + dt, replaced by `target` when it lands within time_tolerance of it (a step shortened to
// reach an output time or t_end lands exactly there, despite rounding).
double advance_time(double t, double dt, double target);

// Whether time t has reached `target` (within time_tolerance(target, dt)).
bool time_reached(double t, double target, double dt);

// The smallest k > current with k·every not yet reached at time t (O(1), no loop): the index of
// the next periodic output or checkpoint. Saturates far below overflow.
std::int64_t next_index_after(double t, double every, std::int64_t current, double dt);

// The index of the first periodic event strictly after t, for a run continued with a changed
// interval (restart with another output.every).
std::int64_t first_index_after(double t, double every);

// False when a step of dt from t cannot advance the run: dt not positive or not finite, or t + dt
// rounds back to t. The run then stops with stop_reason "no_progress" (exit code 3).
bool step_makes_progress(double t, double dt);

// Steps a run from 0 to t_end takes with a step dt when every output interval `every` is landed
// on (steps are shortened to hit k·every): the last step of each interval is a partial one.
double estimated_steps(double t_end, double every, double dt);

}  // namespace capsflow
