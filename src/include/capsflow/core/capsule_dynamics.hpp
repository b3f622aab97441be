#pragma once
// The coupled capsule problem at fixed time: positions x → node velocities v, through the stage
// pipeline of the paper (design.md §3):
//   wall (GSMB: rotation solve, warm-started) → R_s → M(x) q = R_s → v = v∞(x) − S[q].
// With fluid.volume_correction, v ← v − c n_i with c chosen so that the discrete flux
// Σ_e A_e n_e·(v0+v1+v2)/3 — exactly dV/dt of the polyhedron — is zero: the O(h²) flux error of
// the P1 boundary integral (numerics.md §5.1) no longer accumulates into volume drift.
// And the explicit RK2 (Heun) step built on it. Rotations are a slave variable (argmin of the
// bending + shear energy at given x): they are not integrated in time.
#include <map>
#include <memory>
#include <string>

#include "capsflow/core/scene.hpp"
#include "capsflow/core/single_layer.hpp"
#include "capsflow/shell/load_recovery.hpp"
#include "capsflow/shell/wall.hpp"

namespace capsflow {

// Accumulated seconds per phase and solver counters, for progress and the final table.
struct PhaseTimes {
  double wall = 0;   // rotation solve + internal forces R_s
  double load = 0;   // M q = R_s
  double bie_near = 0, bie_far = 0, bie_sources = 0;
  double other = 0;  // flow, updates, diagnostics
  long stages = 0;
  long newton_iterations = 0, cg_iterations = 0, mass_cg_iterations = 0;
};

std::unique_ptr<shell::Wall> make_wall(const Scene& scene, const SurfaceMesh& reference);

class CapsuleDynamics {
 public:
  CapsuleDynamics(const Scene& scene, const SurfaceMesh& reference, int threads = 0);

  // v(x) and, as by-products, the load q and R_s of this evaluation.
  void velocity(const Points& x, Points& v);
  // One Heun step of size dt from x (in place).
  void heun_step(Points& x, double dt);

  const Points& load() const { return q_; }
  const Points& internal_forces() const { return R_; }
  shell::Wall& wall() { return *wall_; }
  const shell::Wall& wall() const { return *wall_; }
  const SingleLayer& single_layer() const { return bie_; }
  const PhaseTimes& times() const { return times_; }
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
  Points R_, q_, u_, v1_, v2_, xs_, nodal_area_normal_;  // scratch, reused across calls
  PhaseTimes times_;
  shell::WallStats last_stats_;
};

}  // namespace capsflow
