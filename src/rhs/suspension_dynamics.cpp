#include "capsflow/core/rhs/suspension_dynamics.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <stdexcept>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/rhs/volume_constraint.hpp"
#include "capsflow/core/scene/boundary_integral_options.hpp"

namespace capsflow {

namespace {
SurfaceMesh part_mesh(const SurfaceSet& set, int k) {
  const SurfacePart& p = set.part(k);
  SurfaceMesh m{set.mesh().vertices.middleRows(p.node_begin, p.nodes),
                set.mesh().triangles.middleRows(p.element_begin, p.elements).array() - static_cast<int>(p.node_begin)};
  return m;
}
}  // namespace

SuspensionDynamics::SuspensionDynamics(const Scene& scene, const SurfaceSet& capsules, int threads)
    : set_(capsules),
      L_(scene.flow.gradient),
      volume_correction_(scene.fluid.volume_correction),
      bie_(capsules, boundary_integral_options(scene, threads)) {
  if (scene.fluid.viscosity_ratio != 1.0)
    throw std::invalid_argument("several capsules: fluid.viscosity_ratio must be 1 (the double layer over several "
                                "surfaces is not implemented)");
  walls_.reserve(static_cast<std::size_t>(set_.size()));
  for (int k = 0; k < set_.size(); ++k) walls_.emplace_back(scene, part_mesh(set_, k));
  x_part_.resize(static_cast<std::size_t>(set_.size()));
  q_.resize(set_.mesh().num_nodes(), 3);
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
  for (int k = 0; k < set_.size(); ++k) {
    const SurfacePart& p = set_.part(k);
    Points& xk = x_part_[static_cast<std::size_t>(k)];
    xk = x.middleRows(p.node_begin, p.nodes);
    WallAndLoad& w = walls_[static_cast<std::size_t>(k)];
    w.solve(xk, hint, counters_, times_, clock);
    q_.middleRows(p.node_begin, p.nodes) = w.load();
  }
  bie_.apply(x, q_, u_);
  if (bie_.cross().inside_nodes() > 0) {  // surfaces that crossed: no velocity of a state that cannot be
    const SurfaceGap& g = bie_.cross().deepest_inside();
    throw SolverFailure(fmt::format("capsules {} and {} overlap: {} node(s) of one inside the other, node {} of capsule {} "
                                    "{:.2g} element sizes deep",
                                    std::min(g.part, g.other), std::max(g.part, g.other), bie_.cross().inside_nodes(), g.node - set_.part(g.part).node_begin,
                                    g.part, g.ratio));
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
