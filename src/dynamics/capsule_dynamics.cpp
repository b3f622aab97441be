#include "capsflow/core/dynamics/capsule_dynamics.hpp"

#include "capsflow/core/dynamics/wall_factory.hpp"

namespace capsflow {

namespace {
SingleLayerOptions bie_options(const Scene& s, int threads) {
  SingleLayerOptions o;
  o.backend = s.fluid.backend;
  o.tolerance = s.fluid.tolerance;
  o.geometry = s.fluid.geometry;
  o.threads = threads;
  return o;
}
}  // namespace

CapsuleDynamics::CapsuleDynamics(const Scene& scene, const SurfaceMesh& reference, int threads)
    : L_(scene.flow.gradient),
      volume_correction_(scene.fluid.volume_correction),
      tri_(reference.triangles),
      wall_(make_wall(scene, reference)),
      mass_(reference.triangles, reference.num_nodes()),
      bie_(reference.triangles, reference.num_nodes(), bie_options(scene, threads)) {}

PhaseTimes CapsuleDynamics::times() const {
  PhaseTimes t = times_;
  t += bie_.times();
  return t;
}

void CapsuleDynamics::velocity(const Points& x, Points& v) {
  Stopwatch clock;
  wall_->forces(x, R_, &last_stats_);
  clock.lap(times_, Phase::Wall);
  counters_.newton_iterations += last_stats_.newton_iterations;
  counters_.cg_iterations += last_stats_.cg_iterations;

  counters_.mass_cg_iterations += mass_.solve(x, R_, q_);
  clock.lap(times_, Phase::Load);

  bie_.apply(x, q_, u_);

  clock.restart();
  v.noalias() = x * L_.transpose() - u_;  // v = v∞ − S[q], v∞ = L x (paper Eq. 34)
  if (volume_correction_) remove_mean_normal_velocity(x, v);
  clock.lap(times_, Phase::Other);
  ++counters_.evaluations;
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

}  // namespace capsflow
