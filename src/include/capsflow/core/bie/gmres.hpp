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
// so each application is told the error it may commit — for a unit vector v_k, an error up to
// kGmresInexactMargin · target / ‖r_k‖ in the weighted norm, r_k the residual before it. The
// error this adds to the final residual is then at most about that margin × the number of
// iterations / the operator's smallest singular value, a small part of the target for the
// well-conditioned second-kind operators it serves. Residuals at (re)starts ask for exact images.
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
  double residual = 0;     // ‖b − A x‖ at exit (the recurrence's value; true residual at restarts)
  double initial_residual = 0;  // ‖b − A x0‖: how good the initial guess was
  bool converged = false;
};

// y = A v (and, when aux is non-null, aux = aux(v)), with an error of at most `allowed_error` · ‖v‖
// (weighted norm); 0: as exact as the operator can be.
using GmresOperator =
    std::function<void(const Eigen::VectorXd& v, Eigen::VectorXd& y, Eigen::VectorXd* aux, double allowed_error)>;
inline constexpr double kGmresInexactMargin = 0.01;

// Solves A x = b from the initial guess in x. `scale` > 0 sets the absolute target
// tolerance · scale (e.g. ‖b‖, or the size of the solution one needs); scale ≤ 0 makes it relative
// to the initial residual (tolerance · ‖b − A x0‖). `aux`, when non-null, receives aux(x) at exit.
// `weight` has one positive entry per unknown.
GmresResult gmres(const GmresOperator& A, const Eigen::VectorXd& b, Eigen::VectorXd& x, const Eigen::VectorXd& weight,
                  double scale, const GmresOptions& opt, Eigen::VectorXd* aux = nullptr);

}  // namespace capsflow
