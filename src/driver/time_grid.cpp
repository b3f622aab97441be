// Time bookkeeping of the run loop (see time_grid.hpp).
#include "capsflow/core/driver/time_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace capsflow {

namespace {
// Far below 2^63: k·every and k + 1 stay exact and never overflow.
constexpr double kMaxIndex = 1e15;
}  // namespace

double time_tolerance(double t, double dt) {
  return 1e-9 * std::abs(dt) + 4 * std::numeric_limits<double>::epsilon() * std::abs(t);
}

double advance_time(double t, double dt, double target) {
  const double next = t + dt;
  return std::abs(next - target) <= time_tolerance(target, dt) ? target : next;
}

bool time_reached(double t, double target, double dt) { return t >= target - time_tolerance(target, dt); }

std::int64_t next_index_after(double t, double every, std::int64_t current, double dt) {
  if (!(every > 0)) return current + 1;
  const double k = std::floor((t + time_tolerance(t, dt)) / every) + 1;  // first k with k·every beyond t
  const double capped = std::isfinite(k) ? std::min(k, kMaxIndex) : kMaxIndex;
  return std::max(current + 1, static_cast<std::int64_t>(capped));
}

std::int64_t first_index_after(double t, double every) {
  if (!(every > 0)) return 1;
  const double k = std::floor(t / every) + 1;
  return static_cast<std::int64_t>(std::clamp(std::isfinite(k) ? k : kMaxIndex, 1.0, kMaxIndex));
}

bool step_makes_progress(double t, double dt) { return std::isfinite(dt) && dt > 0 && t + dt > t; }

double estimated_steps(double t_end, double every, double dt) {
  if (!(dt > 0) || !(every > 0) || !(t_end > 0)) return std::numeric_limits<double>::infinity();
  if (every >= t_end) return std::ceil(t_end / dt);
  const double full = std::floor(t_end / every);  // whole output intervals
  const double rest = t_end - full * every;        // the partial last one (may be 0)
  const double per_interval = std::ceil(every / dt * (1 - 1e-12));  // every/dt = 10 exactly: 10 steps, not 11
  return full * per_interval + (rest > 1e-12 * every ? std::ceil(rest / dt * (1 - 1e-12)) : 0);
}

}  // namespace capsflow
