#pragma once
// Forward static mode: given loads and boundary conditions, find positions and rotations of a
// GSMB shell (same element as the capsule wall) by Newton's method with load stepping.
//
// DOFs per node: 3 translations and 2 rotation increments in the nodal triad (t1, t2, d) (no
// drilling DOF, so no drilling stabilisation). Tangent: exact element Hessians by automatic
// differentiation (element_ad.hpp). Rotations are incremental (Rodrigues), so large rotations are
// exact. Linear systems: Eigen SimplicialLDLT (sparse direct, default: thin-shell stiffness
// matrices have condition numbers ~ (L/h)^2 (L/dx)^4 that defeat plain CG) or Eigen
// ConjugateGradient + IncompleteCholesky (option). The capsule hot path does not use this class.
//
// Loads: dead nodal forces F and nodal moment vectors m, scaled by the load factor. The moment
// work m . omega is exact (conservative) for rotations about a fixed axis (planar problems such
// as the cantilever roll-up); for general 3-D rotations it is a follower-type approximation.
// Globalisation: each Newton increment is scaled so that no nodal rotation exceeds max_rotation,
// then backtracked (Armijo) on the total potential E - lambda (F.u + m.theta), theta the
// accumulated rotation vector (exact work for planar rotations).
// Boundary conditions: translation components fixed at 0 increment; rotation constrained about a
// given spatial axis (omega . a = 0, a projected on the tangent plane; the nodal triad is aligned
// with it), or both rotations fixed (clamped).
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "capsflow/shell/director.hpp"
#include "capsflow/shell/element.hpp"
#include "capsflow/shell/topology.hpp"

namespace capsflow::shell {

struct StaticOptions {
  int max_newton = 30;
  double tol = 1e-7;          ///< ||residual(free DOFs)|| <= tol * ||load(free DOFs)|| (the
                              ///< round-off floor of thin-shell residuals was measured at ~2e-9)
  double floor_tol = 1e-5;    ///< also converged when below this and no longer decreasing
                              ///< (round-off floor: ~3e-7 for the slit annular plate, h = 0.03)
  double max_rotation = 1.0;  ///< damping: largest nodal rotation per Newton iteration (rad)
  bool line_search = false;   ///< Armijo backtracking on the total potential energy (off: on
                              ///< the slit annular plate it stalled in the membrane "valley",
                              ///< 40+ iterations, where plain Newton needs 9-13)
  bool use_cg = false;        ///< CG + incomplete Cholesky instead of the sparse LDLT
  double cg_tol = 1e-12;
};

struct StaticStep {
  double load_factor = 0;
  int newton = 0;
  double residual = 0;
  bool converged = false;
};

class StaticShell {
 public:
  /// D_ref empty: area-weighted nodal normals. Membrane law, thickness h, Poisson ratio nu of the
  /// bending/shear laws (G = law.Gs() / h).
  StaticShell(const Points& X, const Triangles& tri, const Points& D_ref, MembraneLaw law, double h,
              double nu);

  void fix_translation(int node, int comp);
  void fix_rotation_about(int node, const Vec3& axis);
  void fix_rotations(int node);
  void set_forces(const Points& F) { F_ = F; }
  void set_moments(const Points& M) { M_ = M; }

  /// Linear analysis: one Newton step from the current (reference) state under the full load.
  StaticStep solve_linear(const StaticOptions& opt = {});
  /// Nonlinear analysis in `steps` equal load increments up to load factor 1; `on_step` (if not
  /// null) is called after each converged increment.
  template <class F>
  std::vector<StaticStep> solve(int steps, const StaticOptions& opt, F&& on_step) {
    std::vector<StaticStep> out;
    for (int s = 1; s <= steps; ++s) {
      out.push_back(newton(double(s) / steps, opt));
      on_step(out.back());
      if (!out.back().converged) break;
    }
    return out;
  }
  StaticStep newton(double load_factor, const StaticOptions& opt);

  const Points& x() const { return x_; }
  Points displacement() const { return x_ - X_; }
  const Points& directors() const { return triads_.d; }
  const Topology& topology() const { return topo_; }

 private:
  void assemble(double lambda, bool want_K);
  double potential(double lambda) const;  ///< E - lambda (F.u + m.theta_acc)
  void apply_increment(const Eigen::VectorXd& du, double alpha);
  Points X_, x_, F_, M_, theta_acc_;
  NodalTriads triads_;
  MembraneLaw law_;
  Topology topo_;
  std::vector<ElementRef> ref_;
  std::vector<char> fixed_;   // 5 per node
  std::vector<Eigen::Triplet<double>> trip_;
  Eigen::VectorXd r_, fext_;
  Eigen::SparseMatrix<double> K_;
  bool analysed_ = false;
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace capsflow::shell
