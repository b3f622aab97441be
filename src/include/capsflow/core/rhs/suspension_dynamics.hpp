#pragma once
// The right-hand side of several capsules in one unbounded linear flow, at viscosity ratio 1:
// positions x of all capsules (the rows of their SurfaceSet's union) → node velocities
//   v = L (x − c̄) − Σ_k S_k[q_k],
// each capsule's load q_k from its own wall stage (WallAndLoad), the single layers of all
// capsules in one MultiSurfaceSingleLayer (one far field, each capsule's near field, the
// corrections between capsules: docs/boundary-integral.md §4.9). c̄ is the volume centroid of all
// capsules together, the frame point that CapsuleDynamics takes for one capsule (its centroid), so
// that one capsule gives CapsuleDynamics' velocity bit for bit. With fluid.volume_correction
// each capsule's flux is removed on its own rows (its volume is conserved, not only the sum).
// Surfaces never cross silently: a state with a node of one capsule behind the nearest element of
// another (found within 3 element sizes of its surface, as surfaces approach) throws SolverFailure
// naming both capsules.
#include <vector>

#include "capsflow/core/bie/multi_surface_single_layer.hpp"
#include "capsflow/core/geometry/surface_set.hpp"
#include "capsflow/core/phase_times.hpp"
#include "capsflow/core/rhs/capsules_dynamics.hpp"
#include "capsflow/core/rhs/rhs_counters.hpp"
#include "capsflow/core/rhs/right_hand_side.hpp"
#include "capsflow/core/rhs/wall_and_load.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

// A short-range repulsion between capsules (off by default): a node closer than `range` sizes of
// its nearest element of another capsule (range ≤ 3, the cross search's reach) is pushed away from
// it with the nodal force strength · (1 − d/(range h))² (flow units μγ̇a²), along the line from the
// element's nearest point to the node; that point's element takes the opposite force, shared among
// its vertices by its barycentric weights. Force and torque of every pair sum to zero: the capsules'
// momentum balance is untouched. Applied to the walls (WallAndLoad: R_s − f) before M q = R_s.
struct ContactRepulsion {
  double range = 0;  // element sizes; 0: off
  double strength = 1;
};

class SuspensionDynamics final : public CapsulesDynamics {
 public:
  // The scene's flow and fluid keys for all, each capsule's wall its own (Scene::capsule_scene); `capsules` holds their reference
  // surfaces, placed where they start. Throws std::invalid_argument at a viscosity ratio ≠ 1, or a
  // repulsion range outside [0, 3] or a negative strength.
  SuspensionDynamics(const Scene& scene, const SurfaceSet& capsules, int threads = 0, ContactRepulsion contact = {});

  void evaluate(const Points& x, Points& v, const EvaluationHint& hint) override;

  void solve_wall(const Points& x, const EvaluationHint& hint) override;
  Carry carry() const override;
  void restore(Carry c) override;
  // At λ = 1 the fluid carries nothing from one evaluation to the next.
  void save_fluid_state(nlohmann::json&, Eigen::MatrixXd& matrix) const override { matrix.resize(0, 0); }
  void load_fluid_state(const nlohmann::json&, const Eigen::MatrixXd&) override {}

  int capsules() const override { return set_.size(); }
  const SurfaceSet& surfaces() const { return set_; }
  const Points& load() const override { return q_; }  // every capsule's, in the union's rows
  shell::Wall& wall_of(int k) override { return walls_.at(static_cast<std::size_t>(k)).wall(); }
  const shell::Wall& wall_of(int k) const override { return walls_.at(static_cast<std::size_t>(k)).wall(); }
  const SingleLayer& single_layer() const override { return bie_.layer(); }
  const ViscosityRatioSolver* viscosity_ratio_solver() const override { return nullptr; }
  const MultiSurfaceSingleLayer& layers() const { return bie_; }
  const RhsCounters& counters() const override { return counters_; }
  // The closest approach between two capsules at positions x (a cross search; kNone beyond three
  // element sizes), with the nodes of one inside another.
  const CrossNearField& gaps_at(const Points& x);
  // The repulsion's nodal forces of the last evaluation (union rows; empty when off).
  const Points& contact_forces() const { return contact_force_; }
  PhaseTimes times() const override;

 private:
  void solve_walls(const Points& x, const EvaluationHint& hint, Stopwatch& clock);  // q_ at x
  void repulsion(const Points& x);  // contact_force_ from the cross search on x

  SurfaceSet set_;
  Mat3 L_;
  bool volume_correction_;
  std::vector<WallAndLoad> walls_;
  MultiSurfaceSingleLayer bie_;
  ContactRepulsion contact_;
  bool repulsing_;  // a repulsion range and another capsule to repel
  std::vector<Points> x_part_;                  // each capsule's rows of x, for its wall
  Points contact_force_, contact_part_;
  Points q_, u_, area_normal_, part_a_, part_v_;  // scratch, reused across calls
  PhaseTimes times_;
  RhsCounters counters_;
};

}  // namespace capsflow
