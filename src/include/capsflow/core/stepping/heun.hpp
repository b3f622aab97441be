#pragma once
// Explicit second-order Runge–Kutta (Heun), the paper's scheme (docs/time-integration.md §5.1):
//   v1 = f(x),  x* = x + Δt v1,  v2 = f(x*),  x ← x + Δt (v1 + v2)/2.
// Two right-hand-side evaluations per step; stable for Δt below the limit of stepping/stability.hpp.
#include "capsflow/core/rhs/capsule_dynamics.hpp"

namespace capsflow {

class Heun {
 public:
  // One step of size dt from x (in place).
  void step(CapsuleDynamics& rhs, Points& x, double dt);
  static constexpr int evaluations_per_step = 2;

 private:
  Points v1_, v2_, xs_;  // scratch, reused across steps
};

}  // namespace capsflow
