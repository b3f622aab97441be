#include "capsflow/core/capsule_dynamics.hpp"

#include <chrono>

#include "capsflow/shell/gsmb_wall.hpp"

namespace capsflow {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

SingleLayerOptions bie_options(const Scene& s, int threads) {
  SingleLayerOptions o;
  o.backend = s.fluid.backend;
  o.tolerance = s.fluid.tolerance;
  o.threads = threads;
  return o;
}
}  // namespace

std::unique_ptr<shell::Wall> make_wall(const Scene& s, const SurfaceMesh& ref) {
  // Non-dimensional: μ = γ̇ = ℓ = 1, so G_s = 1/Ca_s (design.md §2).
  const shell::MembraneLaw law = shell::make_law(s.wall.law, 1.0 / s.flow.ca_s, s.wall.poisson, s.wall.skalak_c);
  if (s.wall.model == "membrane") return std::make_unique<shell::MembraneWall>(ref.vertices, ref.triangles, law);
  shell::GsmbOptions opt;
  opt.thickness = s.wall.thickness;
  opt.poisson = s.wall.poisson;
  return std::make_unique<shell::GsmbWall>(ref.vertices, ref.triangles, law, opt);
}

CapsuleDynamics::CapsuleDynamics(const Scene& scene, const SurfaceMesh& reference, int threads)
    : L_(scene.flow.gradient),
      wall_(make_wall(scene, reference)),
      mass_(reference.triangles, reference.num_nodes()),
      bie_(reference.triangles, reference.num_nodes(), bie_options(scene, threads)) {}

void CapsuleDynamics::velocity(const Points& x, Points& v) {
  auto t0 = Clock::now();
  wall_->forces(x, R_, &last_stats_);
  times_.wall += since(t0);
  times_.newton_iterations += last_stats_.newton_iterations;
  times_.cg_iterations += last_stats_.cg_iterations;

  t0 = Clock::now();
  times_.mass_cg_iterations += mass_.solve(x, R_, q_);
  times_.load += since(t0);

  const SingleLayerTimings before = bie_.timings();
  bie_.apply(x, q_, u_);
  const SingleLayerTimings& after = bie_.timings();
  times_.bie_near += after.near - before.near;
  times_.bie_far += after.far - before.far;
  times_.bie_sources += after.sources - before.sources;

  t0 = Clock::now();
  v.noalias() = x * L_.transpose() - u_;  // v = v∞ − S[q], v∞ = L x (paper Eq. 34)
  times_.other += since(t0);
  ++times_.stages;
}

void CapsuleDynamics::heun_step(Points& x, double dt) {
  velocity(x, v1_);
  xs_.noalias() = x + dt * v1_;
  velocity(xs_, v2_);
  auto t0 = Clock::now();
  x += (0.5 * dt) * (v1_ + v2_);
  times_.other += since(t0);
}

}  // namespace capsflow
