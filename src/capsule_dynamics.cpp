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
  o.geometry = s.fluid.geometry;
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
      volume_correction_(scene.fluid.volume_correction),
      tri_(reference.triangles),
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
  if (volume_correction_) remove_mean_normal_velocity(x, v);
  times_.other += since(t0);
  ++times_.stages;
}

void CapsuleDynamics::remove_mean_normal_velocity(const Points& x, Points& v) {
  // ∂V/∂x_i = Σ_{e∋i} A_e n_e / 3 =: a_i, so dV/dt = Σ_i a_i·v_i. Subtract c·a_i/|a_i| with
  // c = (Σ a_i·v_i) / (Σ |a_i|): zero flux afterwards, and a uniform normal speed correction.
  nodal_area_normal_.setZero(x.rows(), 3);
  for (Eigen::Index e = 0; e < tri_.rows(); ++e) {
    const int a = tri_(e, 0), b = tri_(e, 1), c = tri_(e, 2);
    const Eigen::RowVector3d an = (x.row(b) - x.row(a)).cross(x.row(c) - x.row(a)) / 6.0;  // A_e n_e / 3
    nodal_area_normal_.row(a) += an, nodal_area_normal_.row(b) += an, nodal_area_normal_.row(c) += an;
  }
  double flux = 0, weight = 0;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    flux += nodal_area_normal_.row(i).dot(v.row(i));
    weight += nodal_area_normal_.row(i).norm();
  }
  const double c = flux / weight;
  for (Eigen::Index i = 0; i < x.rows(); ++i) v.row(i) -= c * nodal_area_normal_.row(i).normalized();
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
