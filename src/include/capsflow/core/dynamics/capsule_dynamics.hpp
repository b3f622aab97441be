#pragma once
// The right-hand side of the capsule problem: positions x → node velocities v = dx/dt, through
// the stage pipeline of the paper (docs/time-integration.md §5.1):
//   wall (GSMB: rotation solve, warm-started) → R_s → M(x) q = R_s → v = v∞(x) − S[q].
// With fluid.volume_correction, v ← v − c n_i with c chosen so that the discrete flux
// Σ_e A_e n_e·(v0+v1+v2)/3 — exactly dV/dt of the polyhedron — is zero: the O(h²) flux error of
// the P1 boundary integral (docs/time-integration.md §5.3) no longer accumulates into volume drift.
// Rotations are a slave variable (argmin of the bending + shear energy at given x): they are not
// integrated in time. Integrators (dynamics/heun.hpp) only call velocity().
#include <memory>

#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/phase_times.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "capsflow/shell/load_recovery.hpp"
#include "capsflow/shell/wall.hpp"

namespace capsflow {

// What the inner solvers of the right-hand side did, summed over evaluations.
struct RhsCounters {
  long evaluations = 0;
  long newton_iterations = 0, cg_iterations = 0, mass_cg_iterations = 0;
};

class CapsuleDynamics {
 public:
  CapsuleDynamics(const Scene& scene, const SurfaceMesh& reference, int threads = 0);

  // v(x) and, as by-products, the load q and R_s of this evaluation.
  void velocity(const Points& x, Points& v);

  const Points& load() const { return q_; }
  const Points& internal_forces() const { return R_; }
  shell::Wall& wall() { return *wall_; }
  const shell::Wall& wall() const { return *wall_; }
  const SingleLayer& single_layer() const { return bie_; }
  // Seconds per phase, the boundary integral's phases included.
  PhaseTimes times() const;
  const RhsCounters& counters() const { return counters_; }
  const shell::WallStats& last_wall_stats() const { return last_stats_; }
  const Mat3& gradient() const { return L_; }

 private:
  void remove_mean_normal_velocity(const Points& x, Points& v);

  Mat3 L_;
  bool volume_correction_;
  Triangles tri_;
  std::unique_ptr<shell::Wall> wall_;
  shell::LoadRecovery mass_;
  SingleLayer bie_;
  Points R_, q_, u_, nodal_area_normal_;  // scratch, reused across calls
  PhaseTimes times_;                      // wall, load, other (the BIE keeps its own)
  RhsCounters counters_;
  shell::WallStats last_stats_;
};

}  // namespace capsflow
