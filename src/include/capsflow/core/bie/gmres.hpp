#pragma once
// Restarted GMRES (Saad & Schultz 1986; Saad, Iterative Methods for Sparse Linear Systems, 2nd ed.,
// Alg. 6.9) in a weighted inner product ⟨a, b⟩ = Σ_k w_k a_k b_k: Arnoldi with modified Gram–Schmidt,
// the least-squares problem by Givens rotations, the solution updated at each restart.
//
// The operator may also return an auxiliary linear image aux(v) of each vector it is applied to;
// GMRES then returns aux(x) for the solution at no extra application (x = x0 + V z ⇒
// aux(x) = aux(x0) + Σ z_j aux(v_j)). The second-kind solve uses it for the rigid-body part of its
// solution (viscosity_ratio.hpp).
//
// Inexact applications (Simoncini & Szyld, SIAM J. Sci. Comput. 25, 2003; Bouras & Frayssé, SIAM
// J. Matrix Anal. Appl. 26, 2005): as the residual falls, the Krylov vectors' images matter less,
// so each application is told the error it may commit — for a unit vector v_k, up to
// kGmresInexactMargin · target / ‖r_k‖ in the weighted norm, r_k the residual before it — and
// returns the error bound it did commit, e_k. With those errors the computed
// residual is not the true one: x = x0 + V z gives b − A x = (computed residual) + E z, E's columns
// the errors (Simoncini & Szyld, §3), so the true residual is within the computed one plus
// Σ_k |z_k| e_k — computable, and GMRES stops only when that sum is within the target. Should the
// bound alone exceed half the target (an operator with a small singular value), the cycle ends,
// the true residual is recomputed exactly and the margin shrinks fourfold for the rest of the
// solve. Residuals at (re)starts ask for exact images.
#include <functional>

#include <Eigen/Core>

namespace capsflow {

struct GmresOptions {
  double tolerance = 1e-8;  // stop when ‖b − A x‖ ≤ tolerance · scale (scale: see gmres())
  int restart = 30;         // Krylov dimension before a restart
  int max_iterations = 300;  // operator applications after the initial residual
  double floor = 0;          // the target residual is never below this (absolute)
};

struct GmresResult {
  int iterations = 0;      // operator applications, the initial residual's excluded
  double residual = 0;     // a bound of ‖b − A x‖ at exit: the recurrence's value plus the inexact
                           // applications' Σ |z_k| e_k (exact, the true residual, at restarts)
  int bound_restarts = 0;  // cycles ended because that bound alone exceeded half the target
  double initial_residual = 0;  // ‖b − A x0‖: how good the initial guess was
  bool converged = false;
};

// y = A v (and, when aux is non-null, aux = aux(v)), with an error of at most `allowed_error` · ‖v‖
// (weighted norm; 0: as exact as the operator can be); returns the bound of the error it committed,
// relative to ‖v‖: within allowed_error, or the operator's own floor where that is larger (the
// double layer's exact FMM); 0 for an exact image. aux(v) may err likewise.
using GmresOperator =
    std::function<double(const Eigen::VectorXd& v, Eigen::VectorXd& y, Eigen::VectorXd* aux, double allowed_error)>;
// The allowance's share of the target: the a-posteriori bound above keeps the true residual within
// the target whatever the margin; a larger one lets more steps take cheap images, at the risk of a
// restart when the committed errors add up. 1 is Bouras & Frayssé's choice; on the second-kind
// solve (whose operator commits at most a quarter of its allowance, viscosity_ratio.cpp) no
// restart was needed at λ = 0.01, 5 and 100 (perf/RESULTS.md §1.6).
inline constexpr double kGmresInexactMargin = 1.0;

// Solves A x = b from the initial guess in x. `scale` > 0 sets the absolute target
// tolerance · scale (e.g. ‖b‖, or the size of the solution one needs); scale ≤ 0 makes it relative
// to the initial residual (tolerance · ‖b − A x0‖). `aux`, when non-null, receives aux(x) at exit.
// `weight` has one positive entry per unknown.
GmresResult gmres(const GmresOperator& A, const Eigen::VectorXd& b, Eigen::VectorXd& x, const Eigen::VectorXd& weight,
                  double scale, const GmresOptions& opt, Eigen::VectorXd* aux = nullptr);

}  // namespace capsflow
