#pragma once
// Load recovery (paper Eq. 44, 48-49a): solve M(x) q = R with the consistent P1 mass matrix of the
// CURRENT surface, M_ij = int_{S(x)} N_i N_j dS (per element (A_e/12)[2 1 1; 1 2 1; 1 1 2]), one
// matrix for the 3 components. q is the load per unit deformed area. The shell's PCG (pcg.hpp) with
// a Jacobi preconditioner on the 3 components at once, initial guess from the lumped mass; the
// sparsity pattern is built once and the values refilled at each call (no allocation after the
// first call).
// Discrete identity: int q dS = 1^T M q = sum_i R_i.
#include "capsflow/shell/pcg.hpp"
#include "capsflow/shell/topology.hpp"
#include "capsflow/shell/types.hpp"

namespace capsflow::shell {

class LoadRecovery {
 public:
  LoadRecovery(const Triangles& tri, Eigen::Index n_nodes);
  /// Consistent mass. Stops when ||R - M q||_F <= tol ||R||_F, or after kMaxIterations (then
  /// last_converged() is false). Returns the CG iterations.
  /// Initial guess: the lumped solution, or the incoming q if set_warm_start(true) and q has
  /// the right size (e.g. the previous stage's load).
  int solve(const Points& x, const Points& R, Points& q, double tol = 1e-12);
  /// APPROXIMATION: lumped (row-sum) mass, q_i = R_i / (sum of A_e/3 around i). First-order
  /// accurate only; it does not satisfy the Galerkin relation with the element forces.
  void solve_lumped(const Points& x, const Points& R, Points& q);
  /// Assemble M(x) (also done by solve); exposed for tests.
  const SpMatR& assemble(const Points& x);
  const SpMatR& mass() const { return M_; }
  double last_relative_residual() const { return relres_; }
  bool last_converged() const { return converged_; }
  /// A Jacobi-preconditioned P1 mass matrix is conditioned independently of h: 14-16 iterations
  /// reach 1e-12 from 1280 to 81 920 elements (perf/shell/results/), so 500 means a degenerate
  /// surface, not a slow solve.
  static constexpr int kMaxIterations = 500;
  void set_warm_start(bool on) { warm_start_ = on; }

 private:
  // M(x) and the lumped masses; with R, also the lumped guess q (sized) in the same team.
  void assemble(const Points& x, const Points* R, Points* q);
  Topology topo_;
  SpMatR M_;
  std::vector<double> area_, lumped_;
  BlockPcg pcg_{1, 3};  // Jacobi, 3 right-hand sides
  double relres_ = 0;
  bool converged_ = true;
  bool warm_start_ = false;
};

}  // namespace capsflow::shell
