#include "capsflow/core/rhs/suspension_dynamics.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <stdexcept>

#include "capsflow/core/bie/point_triangle.hpp"
#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/rhs/volume_constraint.hpp"
#include "capsflow/core/scene/boundary_integral_options.hpp"

namespace capsflow {

SuspensionDynamics::SuspensionDynamics(const Scene& scene, const SurfaceSet& capsules, int threads,
                                       ContactRepulsion contact)
    : set_(capsules),
      L_(scene.flow.gradient),
      volume_correction_(scene.fluid.volume_correction),
      bie_(capsules, boundary_integral_options(scene, threads)),
      contact_(contact),
      repulsing_(contact.range > 0 && capsules.size() > 1) {
  if (!(contact.range >= 0 && contact.range <= kCrossNearRatio) || !(contact.strength >= 0))
    throw std::invalid_argument("several capsules: the repulsion's range must be in [0, 3] element sizes and its "
                                "strength >= 0");
  if (scene.fluid.viscosity_ratio != 1.0)
    throw std::invalid_argument("several capsules: fluid.viscosity_ratio must be 1 (the double layer over several "
                                "surfaces is not implemented)");
  walls_.reserve(static_cast<std::size_t>(set_.size()));
  for (int k = 0; k < set_.size(); ++k) walls_.emplace_back(scene.capsule_scene(k), set_.part_mesh(set_.mesh().vertices, k));
  x_part_.resize(static_cast<std::size_t>(set_.size()));
  q_.resize(set_.mesh().num_nodes(), 3);
}

void SuspensionDynamics::repulsion(const Points& x) {
  bie_.find_pairs(x);
  contact_force_.setZero(x.rows(), 3);
  const Triangles& tri = set_.mesh().triangles;
  for (const SurfaceGap& g : bie_.cross().nearest()) {  // in node order: the same sums on every call
    if (g.inside || !(g.distance > 0)) continue;  // crossed: the evaluation fails below
    const double reach = contact_.range * bie_.cross().element_size(g.element);
    if (g.distance >= reach) continue;
    const Vec3 p = x.row(g.node).transpose();
    const Vec3 a = x.row(tri(g.element, 0)).transpose(), b = x.row(tri(g.element, 1)).transpose(),
               c = x.row(tri(g.element, 2)).transpose();
    const Vec3 foot = closest_point_on_triangle(p, a, b, c);
    const double s = 1 - g.distance / reach;
    const Vec3 F = (contact_.strength * s * s / g.distance) * (p - foot);
    // The foot's barycentric weights (areas of the sub-triangles opposite each vertex).
    const Vec3 n = (b - a).cross(c - a);
    const double w0 = (b - foot).cross(c - foot).dot(n) / n.squaredNorm(), w1 = (c - foot).cross(a - foot).dot(n) / n.squaredNorm();
    const double w[3] = {w0, w1, 1 - w0 - w1};
    contact_force_.row(g.node) += F.transpose();
    for (int v = 0; v < 3; ++v) contact_force_.row(tri(g.element, v)) -= w[v] * F.transpose();
  }
}

void SuspensionDynamics::solve_walls(const Points& x, const EvaluationHint& hint, Stopwatch& clock) {
  for (int k = 0; k < set_.size(); ++k) {
    const SurfacePart& p = set_.part(k);
    Points& xk = x_part_[static_cast<std::size_t>(k)];
    xk = x.middleRows(p.node_begin, p.nodes);
    WallAndLoad& w = walls_[static_cast<std::size_t>(k)];
    if (repulsing_) contact_part_ = contact_force_.middleRows(p.node_begin, p.nodes);
    w.solve(xk, hint, counters_, times_, clock, repulsing_ ? &contact_part_ : nullptr);
    q_.middleRows(p.node_begin, p.nodes) = w.load();
  }
}

void SuspensionDynamics::solve_wall(const Points& x, const EvaluationHint& hint) {
  Stopwatch clock;
  if (repulsing_) repulsion(x);
  solve_walls(x, hint, clock);
  ++counters_.wall_solves;
}

CapsulesDynamics::Carry SuspensionDynamics::carry() const {
  Carry c;
  for (const WallAndLoad& w : walls_) c.walls.push_back(w.wall().state());
  c.load = q_;
  return c;
}

void SuspensionDynamics::restore(Carry c) {
  for (std::size_t k = 0; k < walls_.size(); ++k) {
    walls_[k].wall().set_state(c.walls.at(k));
    const SurfacePart& p = set_.part(static_cast<int>(k));
    walls_[k].set_load(c.load.middleRows(p.node_begin, p.nodes));
  }
  q_ = std::move(c.load);
}

const CrossNearField& SuspensionDynamics::gaps_at(const Points& x) {
  bie_.find_pairs(x);
  return bie_.cross();
}

PhaseTimes SuspensionDynamics::times() const {
  PhaseTimes t = times_;
  t += bie_.layer().times();
  return t;
}

void SuspensionDynamics::evaluate(const Points& x, Points& v, const EvaluationHint& hint) {
  if (x.rows() != set_.mesh().num_nodes())
    throw std::invalid_argument("several capsules: positions must have one row per node of every capsule");
  Stopwatch clock;
  if (repulsing_) repulsion(x);
  solve_walls(x, hint, clock);  // the repulsion's time goes with the walls'
  bie_.apply(x, q_, u_, repulsing_);
  if (bie_.cross().inside_nodes() > 0) {  // surfaces that crossed: no velocity of a state that cannot be
    const SurfaceGap& g = bie_.cross().deepest_inside();
    throw SolverFailure(fmt::format("capsules {} and {} overlap: {} node(s) of one inside the other, node {} of capsule {} "
                                    "{:.2g} element sizes deep",
                                    std::min(g.part, g.other) + 1, std::max(g.part, g.other) + 1, bie_.cross().inside_nodes(),
                                    g.node - set_.part(g.part).node_begin, g.part + 1, g.ratio));
  }
  clock.restart();
  // The imposed flow relative to the capsules' common volume centroid (CapsuleDynamics::evaluate).
  const Vec3 c = volume_moments(x, set_.mesh().triangles).centroid;
  v.noalias() = (x.rowwise() - c.transpose()) * L_.transpose() - u_;
  if (volume_correction_) {
    volume_gradient(x, set_.mesh().triangles, area_normal_);
    for (int k = 0; k < set_.size(); ++k) {  // each capsule's flux on its own rows
      const SurfacePart& p = set_.part(k);
      part_a_ = area_normal_.middleRows(p.node_begin, p.nodes);
      part_v_ = v.middleRows(p.node_begin, p.nodes);
      remove_normal_flux(part_a_, part_v_);
      v.middleRows(p.node_begin, p.nodes) = part_v_;
    }
  }
  clock.lap(times_, Phase::Other);
  ++counters_.evaluations;
  if (!v.allFinite()) throw SolverFailure("non-finite velocity");
}

}  // namespace capsflow
