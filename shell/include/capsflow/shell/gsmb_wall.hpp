#pragma once
// GSMB capsule wall (paper §2.6, §4.1) discretised with MITC3 triangles (element.hpp).
//
// Unknowns besides the imposed positions x: one unit director d_i per node with a nodal tangent
// triad (t1_i, t2_i, d_i); 2 rotation DOFs per node, increments w = w1 t1 + w2 t2 applied with
// Rodrigues (exact for any angle). Reference directors: area-weighted nodal normals, or given.
//
// Rotation solve (paper Eq. 49b-53): Newton on R_theta(x, theta) = 0 at fixed x, each linear
// system K_tt dw = -R_theta solved by CG with a 2x2 block-Jacobi preconditioner on the sparse
// theta-theta tangent (pattern built once). K_tt = material part T^T (d2E/dd2) T (SPD) plus the
// geometric part -(g_i.d_i) I_2 of the exponential map at each node (bounded below by -1/2 of the
// node's material diagonal, so the diagonal stays positive far from equilibrium). Keeping the
// geometric part gives quadratic convergence; dropping its negative part (a modified Newton) was
// measured to converge only linearly, rate ~0.1, on a strongly deformed sphere (10 instead of 5
// iterations from the reference, 6 instead of 2 from a warm start). Warm start: the directors of
// the previous call.
//
// Convergence: max_i |R_theta,i| / K_ii <= newton_tol. This is the Jacobi estimate (in radians)
// of the remaining Newton correction, i.e. the paper's criterion |theta_{i+1} - theta_i| < 1e-7
// (Eq. 53) evaluated before the step. Default 1e-10: 1000x tighter than the paper because an
// error in theta is amplified by h D in the load (docs/shell.md §2.8.3); with quadratic
// convergence the extra cost is at most one Newton step.
#include <Eigen/SparseCore>
#include <array>
#include <functional>
#include <vector>

#include "capsflow/shell/director.hpp"
#include "capsflow/shell/pcg.hpp"
#include "capsflow/shell/wall.hpp"

namespace capsflow::shell {

struct GsmbOptions {
  double thickness = 0.03;   ///< h = alpha (in units of l)
  double poisson = 0.5;      ///< nu of the bending/shear Hooke laws (paper: nu = nu_s)
  double newton_tol = 1e-10; ///< max |R_theta|/K_diag (radians), see above
  // Usually 1–4 iterations; leaving the saddle of a mesh-scale fold took 45–47 (docs/shell.md §2.4).
  int max_newton = 100;
  double cg_tol = 1e-6;      ///< relative residual of each Newton linear system (inexact Newton)
  int max_cg = 2000;
  double max_step = 0.5;     ///< damped Newton: largest rotation increment per step (radians)
  bool predict = true;       ///< before Newton, rotate each triad with its node's facet normal
                             ///< (minimal rotation from the normal at the last solve to the current)
  bool geometric_tangent = true;  ///< add the geometric part -(g.d) I_2 to K_tt (see above)
};

/// One Newton step of a rotation solve, reported to the caller's trace (GsmbWall::set_trace).
struct NewtonStep {
  int iteration = 0;         ///< 0: the residual at the predicted triads
  double residual = 0;       ///< max_i |R_theta,i| / K_ii (radians) before the correction
  double geometric_floor = 0;  ///< floor of the geometric tangent term in use
  int cg_iterations = 0;     ///< of the correction that follows, both attempts if CG stalled and
                             ///< was restarted at the safer floor (0: none, the solve stops here)
  double cg_relres = 0;      ///< its relative residual
};

class GsmbWall : public Wall {
 public:
  GsmbWall(const Points& X_ref, const Triangles& tri, MembraneLaw law, GsmbOptions opt);
  /// Same with given reference unit directors (e.g. analytic normals).
  GsmbWall(const Points& X_ref, const Triangles& tri, const Points& D_ref, MembraneLaw law,
           GsmbOptions opt);

  void forces(const Points& x, Points& R_s, WallStats* stats = nullptr) override;
  WallEnergies energies(const Points& x) const override;
  void nodal_energy_maps(const Points& x, Eigen::VectorXd& Em, Eigen::VectorXd& Eb,
                         Eigen::VectorXd& Esh) const override;
  /// [d (3N), t1 (3N), t2 (3N), facet normals of the last solve (3N)] node by node.
  Eigen::VectorXd state() const override;
  void set_state(const Eigen::VectorXd& s) override;
  void restart_rotations(const Points& x) override;
  /// The stage predictor: each kept director is turned by the smallest rotation from its node's
  /// normal at that solve to the current one (the default predictor, per slot), the predicted
  /// director is the normalised weighted sum, and the triad is turned onto it.
  void set_warm_start(const WarmStart& w) override { warm_ = w; }

  // ---- lower-level access (tests, forward static mode, diagnostics) ----
  /// Rotation solve only (positions fixed); leaves R_s of the final state in the internal buffer.
  WallStats solve_rotations(const Points& x);
  /// One element pass at the current directors: x-forces fx = dE/dx (all parts), rotation residual
  /// R_theta (2N, in the nodal triads) and, if want_K, the theta-theta tangent (see tangent()).
  /// want_fx = false skips the membrane part and the x-forces (fx left stale).
  void evaluate(const Points& x, Points* fx, Eigen::VectorXd* R_theta, bool want_K,
                bool want_fx = true);
  /// Tangent of the last evaluate(want_K = true); include_geometric as in the options.
  const SpMatR& tangent() const { return K_; }
  /// Rotate the nodal triads by the increments w (2N: w1, w2 per node in (t1, t2)).
  void rotate(const Eigen::VectorXd& w);
  void set_directors(const Points& d);  ///< sets d (normalised) and rebuilds the triads
  const Points& directors() const { return triads_.d; }
  const Points& reference_directors() const { return D_; }
  const Points& t1() const { return triads_.t1; }
  const Points& t2() const { return triads_.t2; }
  /// Director forces g_i = dE/dd_i of the last evaluate() (directors as free vectors).
  const Points& director_forces() const { return g_; }
  const std::vector<ElementRef>& elements() const { return ref_; }
  const Topology& topology() const { return topo_; }
  const MembraneLaw& law() const { return law_; }
  const GsmbOptions& options() const { return opt_; }
  GsmbOptions& options() { return opt_; }
  /// Called once per Newton step of every solve (none by default): the residual history for a
  /// log or a test, without changing the solve.
  void set_trace(std::function<void(const NewtonStep&)> trace) { trace_ = std::move(trace); }

 private:
  void init(const Points& X, const Points& D);
  void element_energies(const Points& x, std::vector<double>* em, std::vector<double>* eb,
                        std::vector<double>* es) const;
  MembraneLaw law_;
  GsmbOptions opt_;
  Topology topo_;
  std::vector<ElementRef> ref_;
  // Newton iterations on the rotations from the current triads, the geometric tangent term floored at
  // −floor (falling back to the safer floor if CG stalls); adds to st, clears st.converged on failure.
  // What an element pass does first, node by node, in the same team: nothing, the predictor
  // (solve_rotations), or the Newton step dw_ (scaled to max_step).
  enum class Prologue { None, Predict, Step };
  // `first` is the prologue of the first pass (the predictor).
  void newton(const Points& x, double floor, WallStats& st, Prologue first);
  // One element pass after the prologue (see evaluate()); returns max_i |R_theta,i| / K_ii.
  double pass(const Points& x, Prologue prologue, bool want_K, bool want_fx);
  // The predictor of node i from the kept solutions of warm_ (set_warm_start), in the first pass.
  void predict_from_kept(int i, const Vec3& nc);
  bool kept_usable() const;
  Points D_, n_prev_, n_cur_;  // reference directors; facet normals of the last and current solve
  WarmStart warm_;             // for the next solve only
  std::array<Points, WarmStart::kSlots> kept_d_, kept_n_;  // kept directors and their solves' normals
  NodalTriads triads_;
  NodalTriads start_;  // predicted triads at the start of a solve (retry from them)
  Points fx_, g_;
  // What one element of the pass gives its three nodes: f[a] = (x-forces, director forces) of
  // local node a, K the material theta-theta block (when the pass builds the tangent).
  struct ElementOut {
    double f[3][6];
    double K[6][6];
  };
  std::vector<ElementOut> eout_;
  SpMatR K_;
  std::vector<int> row_base_, row_len2_;  // K value index of node-row i: 4*adj_ptr[i], 2*deg(i)
  Eigen::VectorXd Rth_, dw_, kdiag_;
  BlockPcg pcg_{2};
  int last_newton_ = 0;  // Newton corrections of the previous call (work-saving heuristic only)
  double geometric_floor_ = 0;  // floor of the geometric tangent term, set at the start of each solve (gsmb_wall.cpp)
  mutable std::vector<double> partial_;
  std::vector<double> thread_max_;  // one maximum per thread of a pass
  std::function<void(const NewtonStep&)> trace_;
};

}  // namespace capsflow::shell
