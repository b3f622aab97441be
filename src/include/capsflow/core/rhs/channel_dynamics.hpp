#pragma once
// The right-hand side of one capsule in a channel's Poiseuille flow (docs/channel.md §4), at
// viscosity ratio 1: positions x of the capsule → node velocities
//
//   v = u_P(x) − S_C[q](x) + S_W[f](x) − U e_x,     S_W[f] = S_C[q] on the wall,
//
// the disturbance formulation of docs/channel.md §3.1: u_P the channel's Poiseuille flow
// (theory/poiseuille.hpp, mean velocity V), q the capsule's load from its wall stage (WallAndLoad),
// S_C its single layer (at its own nodes as for a capsule alone; at the wall's nodes as a flow
// off its surface, bie/off_surface.hpp), f the channel wall's disturbance traction (FixedWall,
// warm-started from the last evaluation), and U the axial velocity of the capsule's volume
// centroid (the exact rate of the polyhedron's centroid, geometry/measures.hpp: centroid_rate).
// Subtracting U keeps the capsule where it started along the channel: the frame moves with it,
// and the channel — straight, so the same wherever the frame is — with its caps always the same
// distance ahead and behind. axial_velocity() is U, the capsule's speed through the channel.
// A constricted duct is not the same wherever the frame is: there the frame is the lab's (no
// −U e_x), u_P is the inlet's Poiseuille flow, and the wall's disturbance also cancels u_P where
// the constriction's wall runs inside the inlet's cross-section (the wall velocity −u_P, §3.5).
// With fluid.volume_correction the capsule's flux is removed as for a capsule alone.
//
// The wall traction's warm start is not part of carry(): an evaluation off the trajectory (a
// probe, an output) moves the next solve's starting point, within the GMRES tolerance.
//
// Throws SolverFailure when a node leaves the channel's cross-section or comes within 1e-3
// element sizes of the wall (off_surface.hpp's too-close limit), the wall's solve does not
// converge, or (lab frame) the capsule comes within a channel radius of the outlet cap.
#include <limits>
#include <memory>

#include "capsflow/core/bie/fixed_wall.hpp"
#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/mesh/channel.hpp"
#include "capsflow/core/phase_times.hpp"
#include "capsflow/core/rhs/capsules_dynamics.hpp"
#include "capsflow/core/rhs/rhs_counters.hpp"
#include "capsflow/core/rhs/wall_and_load.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

struct ChannelFlow {
  ChannelGeometry geometry;
  double mean_velocity = 1;  // V
};

class ChannelDynamics final : public CapsulesDynamics {
 public:
  // The capsule's wall and fluid keys are the scene's; the channel is `channel`. Throws
  // std::invalid_argument at a viscosity ratio ≠ 1.
  ChannelDynamics(const Scene& scene, const SurfaceMesh& reference, const ChannelFlow& channel, int threads = 0,
                  std::unique_ptr<shell::Wall> wall = nullptr);
  ~ChannelDynamics() override;

  void evaluate(const Points& x, Points& v, const EvaluationHint& hint) override;
  void solve_wall(const Points& x, const EvaluationHint& hint) override;
  Carry carry() const override;
  void restore(Carry c) override;
  // The wall's traction, the warm start of its solve: a restart continues bit for bit.
  void save_fluid_state(nlohmann::json& extra, Eigen::MatrixXd& matrix) const override;
  void load_fluid_state(const nlohmann::json& extra, const Eigen::MatrixXd& matrix) override;

  int capsules() const override { return 1; }
  const Points& load() const override { return wall_load_.load(); }
  shell::Wall& wall_of(int) override { return wall_load_.wall(); }
  const shell::Wall& wall_of(int) const override { return wall_load_.wall(); }
  const SingleLayer& single_layer() const override { return bie_; }
  const ViscosityRatioSolver* viscosity_ratio_solver() const override { return nullptr; }
  PhaseTimes times() const override;
  const RhsCounters& counters() const override { return counters_; }

  const ChannelFlow& channel() const { return channel_; }
  const FixedWall& channel_wall() const { return *channel_wall_; }
  double axial_velocity() const { return axial_velocity_; }  // U of the last evaluation
  // In the lab frame (a constriction) the capsule travels towards the outlet cap, whose zero
  // disturbance it would feel within about a channel radius: a run stops (stop_reason "outlet")
  // once an accepted step brings the capsule's front within kOutletStopClearance radii of the cap,
  // and evaluate() refuses stages within one radius (a step too long to stop in time is retried).
  static constexpr double kOutletStopClearance = 1.25;
  bool reached_outlet(const Points& x) const;
  const FixedWallSolve& last_wall_solve() const { return last_solve_; }
  long wall_gmres_iterations() const { return wall_gmres_iterations_; }  // over all evaluations
  // The channel's Poiseuille velocity (along x) at a point, 0 outside the cross-section.
  double poiseuille(const Vec3& p) const;
  // The smallest distance from a capsule node to the channel wall, in wall element sizes, of the
  // last evaluation.
  double wall_gap() const { return wall_gap_; }
  // The additional pressure drop Δp⁺ the capsule causes (in μV/ℓ), of the last evaluation, by the
  // reciprocal theorem with Poiseuille's flow (docs/channel.md §4): Q Δp⁺ = ∫_C q·u_P dS, Q the
  // flux; and the same read from the wall's traction (the free pressure_drop_from_caps below) — a
  // check through the wall's solve, with the caps' O(h) error; less the empty channel's, which is
  // not zero in a constriction. In a constriction the undisturbed flow of the reciprocal theorem
  // is the empty constriction's, u_P + S_W[f₀] + D[u_w].
  double pressure_drop() const { return pressure_drop_; }
  double pressure_drop_from_caps() const;

 private:
  ChannelFlow channel_;
  bool volume_correction_;
  Triangles tri_;
  WallAndLoad wall_load_;
  SingleLayer bie_;
  ChannelMesh mesh_;
  std::unique_ptr<FixedWall> channel_wall_;
  Points u_, induced_, from_wall_, area_normal_;  // scratch
  FixedWallSolve last_solve_;
  double axial_velocity_ = 0, pressure_drop_ = 0;
  double wall_gap_ = std::numeric_limits<double>::infinity();  // none before the first evaluation
  double empty_pressure_drop_ = 0;  // the caps' pressure drop without a capsule (constriction)
  Points empty_traction_, extra_;   // the empty constriction's traction; scratch
  long wall_gmres_iterations_ = 0;
  PhaseTimes times_;
  RhsCounters counters_;
};

// A channel's added pressure drop read from its wall's traction (f = σ·n at the wall's nodes): the
// difference of the caps' mean pressure −f·n over their nodes more than 1.5 wall elements from the
// rim, where the P1 traction need not turn with the normal (docs/channel.md §3.3).
double pressure_drop_from_caps(const ChannelMesh& channel, const Points& traction);

}  // namespace capsflow
