#include "capsflow/core/stepping/heun.hpp"

namespace capsflow {

void Heun::step(CapsuleDynamics& rhs, Points& x, double dt) {
  rhs.velocity(x, v1_);
  xs_.noalias() = x + dt * v1_;
  rhs.velocity(xs_, v2_);
  x += (0.5 * dt) * (v1_ + v2_);
}

}  // namespace capsflow
