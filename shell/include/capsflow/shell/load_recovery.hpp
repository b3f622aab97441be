#pragma once
// Load recovery (paper Eq. 44, 48-49a): solve M(x) q = R with the consistent P1 mass matrix of the
// CURRENT surface, M_ij = int_{S(x)} N_i N_j dS (per element (A_e/12)[2 1 1; 1 2 1; 1 1 2]), one
// matrix for the 3 components. q is the load per unit deformed area. CG with a Jacobi
// preconditioner, initial guess from the lumped mass; the sparsity pattern is built once and the
// values refilled at each call (no allocation after the first call).
// Discrete identity: int q dS = 1^T M q = sum_i R_i.
#include "capsflow/shell/pcg.hpp"
#include "capsflow/shell/topology.hpp"
#include "capsflow/shell/types.hpp"

namespace capsflow::shell {

class LoadRecovery {
 public:
  LoadRecovery(const Triangles& tri, Eigen::Index n_nodes);
  /// Consistent mass. Stops when ||R - M q||_F <= tol ||R||_F. Returns the CG iterations.
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
  void set_warm_start(bool on) { warm_start_ = on; }

 private:
  Topology topo_;
  SpMatR M_;
  std::vector<double> area_, lumped_, partial_, bbpart_;
  double relres_ = 0;
  bool warm_start_ = false;
  // work vectors for the 3-column CG
  std::vector<double> r_, z_, p_, Ap_;
};

}  // namespace capsflow::shell
