#include "capsflow/core/rhs/channel_dynamics.hpp"

#include <fmt/core.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/rhs/volume_constraint.hpp"
#include "capsflow/core/scene/boundary_integral_options.hpp"
#include "capsflow/core/theory/poiseuille.hpp"

namespace capsflow {

ChannelDynamics::ChannelDynamics(const Scene& scene, const SurfaceMesh& reference, const ChannelFlow& channel,
                                 int threads, std::unique_ptr<shell::Wall> wall)
    : channel_(channel),
      volume_correction_(scene.fluid.volume_correction),
      tri_(reference.triangles),
      wall_load_(scene, reference, std::move(wall)),
      bie_(reference.triangles, reference.num_nodes(), boundary_integral_options(scene, threads)),
      mesh_(make_channel_mesh(channel.geometry)) {
  if (scene.fluid.viscosity_ratio != 1.0)
    throw std::invalid_argument("channel: fluid.viscosity_ratio must be 1 (the double layer with a channel wall is not implemented)");
  FixedWallOptions o;
  o.layer = boundary_integral_options(scene, threads);
  o.layer.geometry = SurfaceGeometry::Flat;  // the wall has edges (the caps' rims): flat facets only
  o.gmres.tolerance = scene.fluid.tolerance;  // the far field's promise: a tighter wall buys nothing
  // The disturbance cancels Poiseuille's flow on the side wall — nothing on a straight channel's,
  // −u_P where a constriction's wall runs inside the inlet's cross-section — and vanishes on the
  // caps, through which u_P enters and leaves (docs/channel.md §3.5).
  Points wall_velocity = Points::Zero(mesh_.mesh.num_nodes(), 3);
  for (Eigen::Index i = 0; i < wall_velocity.rows(); ++i)
    if (mesh_.node_region[static_cast<std::size_t>(i)] == ChannelRegion::Side)
      wall_velocity(i, 0) = -poiseuille(mesh_.mesh.vertices.row(i).transpose());
  channel_wall_ = std::make_unique<FixedWall>(mesh_.mesh, wall_velocity, o);
  if (!channel.geometry.straight()) {  // the empty constriction's traction: the capsule's Δp⁺ is measured from it
    const FixedWallSolve empty = channel_wall_->solve(nullptr, channel_.mean_velocity);
    if (!empty.converged)
      throw SolverFailure(fmt::format("channel wall GMRES did not converge on the empty constriction (relative residual {:.1e})",
                                      empty.residual));
    empty_pressure_drop_ = capsflow::pressure_drop_from_caps(mesh_, channel_wall_->traction());
    empty_traction_ = channel_wall_->traction();
  }
}

ChannelDynamics::~ChannelDynamics() = default;

double ChannelDynamics::poiseuille(const Vec3& p) const {
  const ChannelGeometry& g = channel_.geometry;
  if (distance_from_axis(g, p.y(), p.z()) >= g.radius) return 0.0;
  return g.shape == ChannelShape::Tube ? tube_poiseuille_velocity(std::hypot(p.y(), p.z()), g.radius, channel_.mean_velocity)
                                       : duct_poiseuille_velocity(p.y(), p.z(), g.radius, channel_.mean_velocity);
}

void ChannelDynamics::solve_wall(const Points& x, const EvaluationHint& hint) {
  Stopwatch clock;
  wall_load_.solve(x, hint, counters_, times_, clock);
  ++counters_.wall_solves;
}

CapsulesDynamics::Carry ChannelDynamics::carry() const {
  return {{wall_load_.wall().state()}, wall_load_.load(), {}, channel_wall_->traction()};
}

void ChannelDynamics::restore(Carry c) {
  wall_load_.wall().set_state(c.walls.at(0));
  wall_load_.set_load(std::move(c.load));
  if (c.channel_traction.size() > 0) channel_wall_->set_traction(c.channel_traction);
}

void ChannelDynamics::save_fluid_state(nlohmann::json& extra, Eigen::MatrixXd& matrix) const {
  matrix = channel_wall_->traction();  // the wall solve's warm start: a restart continues bit for bit
  extra["fluid_state"] = {{"channel_traction", true}};
}

void ChannelDynamics::load_fluid_state(const nlohmann::json& extra, const Eigen::MatrixXd& matrix) {
  if (!extra.contains("fluid_state") || !extra.at("fluid_state").value("channel_traction", false)) return;
  if (matrix.rows() != channel_wall_->traction().rows() || matrix.cols() != 3)
    throw std::runtime_error(fmt::format("checkpoint: the channel wall's traction has {}×{} values for a wall of {} nodes",
                                         matrix.rows(), matrix.cols(), channel_wall_->traction().rows()));
  channel_wall_->set_traction(matrix);
}

PhaseTimes ChannelDynamics::times() const {
  PhaseTimes t = times_;
  t += bie_.times();
  return t;
}

void ChannelDynamics::evaluate(const Points& x, Points& v, const EvaluationHint& hint) {
  Stopwatch clock;
  wall_load_.solve(x, hint, counters_, times_, clock);
  const Points& q = wall_load_.load();
  bie_.apply(x, q, u_);  // S_C[q] at the capsule's nodes

  // The wall cancels the capsule's disturbance on itself: S_W[f] = S_C[q] at the wall's nodes.
  clock.restart();
  OffSurfaceReport on_wall;
  evaluate_off_surface(bie_, x, q, mesh_.mesh.vertices, induced_, &on_wall);
  last_solve_ = channel_wall_->solve(&induced_, channel_.mean_velocity);
  wall_gmres_iterations_ += last_solve_.iterations;
  if (!last_solve_.converged)
    throw SolverFailure(fmt::format("channel wall GMRES did not converge (relative residual {:.1e} after {} iterations)",
                                    last_solve_.residual, last_solve_.iterations));
  OffSurfaceReport near_wall;
  channel_wall_->velocity_at(x, from_wall_, &near_wall);  // S_W[f] at the capsule's nodes
  wall_gap_ = std::numeric_limits<double>::infinity();
  for (const double r : near_wall.distance_ratio) wall_gap_ = std::min(wall_gap_, r);
  if (near_wall.too_close > 0 || on_wall.too_close > 0)
    throw SolverFailure(fmt::format("the capsule touches the channel wall ({} node(s) within {:.0e} wall element sizes)",
                                    near_wall.too_close, OffSurfaceReport::min_ratio));

  v = from_wall_ - u_;
  const Eigen::VectorXd area = nodal_areas(x, tri_);
  double work = 0;  // ∫ q·u_P dS, the load P1 and u_P at the nodes (lumped: O(h²) as the rest)
  const ChannelGeometry& g = channel_.geometry;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const Vec3 p = x.row(i).transpose();
    if (relative_distance_from_axis(g, p) >= 1)
      throw SolverFailure(fmt::format("capsule node {} left the channel's cross-section", i));
    const double up = poiseuille(p);
    v(i, 0) += up;
    work += area[i] * q(i, 0) * up;
  }
  if (!g.straight()) {
    // The undisturbed flow is not u_P in a constriction but u_P + S_W[f₀] + D[u_w], f₀ the empty
    // constriction's traction: from_wall_ holds S_W[f] + D[u_w], so the undisturbed flow's
    // difference from u_P is from_wall_ − S_W[f − f₀].
    channel_wall_->single_layer_at(channel_wall_->traction() - empty_traction_, x, extra_);
    for (Eigen::Index i = 0; i < x.rows(); ++i) work += area[i] * q.row(i).dot(from_wall_.row(i) - extra_.row(i));
  }
  // Δp⁺ by the reciprocal theorem with the undisturbed flow (docs/channel.md §4).
  pressure_drop_ = work / (channel_.mean_velocity * channel_cross_section_area(g));
  if (volume_correction_) {
    volume_gradient(x, tri_, area_normal_);
    remove_normal_flux(area_normal_, v);
  }
  axial_velocity_ = centroid_rate(x, tri_, v).x();
  if (g.straight()) {
    // The frame moves with the capsule's centroid along the channel (a uniform velocity has no flux).
    v.col(0).array() -= axial_velocity_;
  } else if (x.col(0).maxCoeff() > 0.5 * g.length - g.radius) {
    // In the lab frame the capsule travels towards the outlet; within a radius of it the cap's
    // zero disturbance would be felt (the run stops before, reached_outlet).
    throw SolverFailure(fmt::format("the capsule reached x1 = {:.3g}, within channel.radius of the outlet cap at {:.3g}",
                                    x.col(0).maxCoeff(), 0.5 * g.length));
  }
  clock.lap(times_, Phase::Other);
  ++counters_.evaluations;
  if (!v.allFinite()) throw SolverFailure("non-finite velocity");
}

bool ChannelDynamics::reached_outlet(const Points& x) const {
  const ChannelGeometry& g = channel_.geometry;
  return !g.straight() && x.col(0).maxCoeff() > 0.5 * g.length - kOutletStopClearance * g.radius;
}

double ChannelDynamics::pressure_drop_from_caps() const {
  return capsflow::pressure_drop_from_caps(mesh_, channel_wall_->traction()) - empty_pressure_drop_;
}

double pressure_drop_from_caps(const ChannelMesh& channel, const Points& traction) {
  const Points n = nodal_normals(channel.mesh);
  const Eigen::VectorXd a = nodal_areas(channel.mesh);
  const ChannelGeometry& g = channel.geometry;
  const Points& f = traction;
  double p_in = 0, p_out = 0, a_in = 0, a_out = 0;
  for (Eigen::Index i = 0; i < f.rows(); ++i) {
    const ChannelRegion region = channel.node_region[static_cast<std::size_t>(i)];
    const double from_axis = distance_from_axis(g, channel.mesh.vertices(i, 1), channel.mesh.vertices(i, 2));
    if (region == ChannelRegion::Side || from_axis > g.radius - 1.5 * g.element_size) continue;
    const double p = -f.row(i).dot(n.row(i));
    if (region == ChannelRegion::Inlet)
      p_in += p * a[i], a_in += a[i];
    else
      p_out += p * a[i], a_out += a[i];
  }
  return a_in > 0 && a_out > 0 ? p_in / a_in - p_out / a_out : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace capsflow
