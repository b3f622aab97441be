#include "capsflow/core/bie/gmres.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

namespace capsflow {

GmresResult gmres(const GmresOperator& A, const Eigen::VectorXd& b, Eigen::VectorXd& x, const Eigen::VectorXd& weight,
                  double scale, const GmresOptions& opt, Eigen::VectorXd* aux) {
  using Eigen::VectorXd;
  const Eigen::Index n = b.size();
  const int m = std::max(1, opt.restart);
  auto dot = [&](const VectorXd& a, const VectorXd& c) { return (weight.array() * a.array() * c.array()).sum(); };
  auto norm = [&](const VectorXd& a) { return std::sqrt(dot(a, a)); };
  double target = opt.tolerance * scale;

  GmresResult res;
  std::vector<VectorXd> V(static_cast<size_t>(m + 1)), W;  // Arnoldi basis, aux images
  if (aux) W.resize(static_cast<size_t>(m));
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m + 1, m);
  VectorXd cs(m), sn(m), g(m + 1), Av(n), r(n), z, committed(m);
  double margin = kGmresInexactMargin;
  while (true) {
    // True residual at every (re)start.
    A(x, Av, aux, 0.0);
    r = b - Av;
    double beta = norm(r);
    res.residual = beta;
    if (res.iterations == 0) {
      res.initial_residual = beta;
      if (scale <= 0) target = opt.tolerance * beta;
    }
    target = std::max(target, opt.floor);
    if (beta <= target) {
      res.converged = true;
      return res;
    }
    if (res.iterations >= opt.max_iterations) return res;
    V[0] = r / beta;
    g.setZero();
    g[0] = beta;
    int k = 0;
    bool done = false;
    for (; k < m && res.iterations < opt.max_iterations; ++k) {
      // ‖r_k‖ = |g[k]|; the target is final after the first residual.
      const double allowed = margin * target / std::abs(g[k]);
      committed[k] = A(V[static_cast<size_t>(k)], Av, aux ? &W[static_cast<size_t>(k)] : nullptr, allowed);
      ++res.iterations;
      for (int j = 0; j <= k; ++j) {  // modified Gram–Schmidt
        H(j, k) = dot(Av, V[static_cast<size_t>(j)]);
        Av -= H(j, k) * V[static_cast<size_t>(j)];
      }
      const double h_next = norm(Av);
      H(k + 1, k) = h_next;
      if (h_next > 0) V[static_cast<size_t>(k + 1)] = Av / h_next;
      for (int j = 0; j < k; ++j) {  // previous rotations on the new column
        const double t = cs[j] * H(j, k) + sn[j] * H(j + 1, k);
        H(j + 1, k) = -sn[j] * H(j, k) + cs[j] * H(j + 1, k);
        H(j, k) = t;
      }
      const double d = std::hypot(H(k, k), H(k + 1, k));
      cs[k] = d > 0 ? H(k, k) / d : 1.0;
      sn[k] = d > 0 ? H(k + 1, k) / d : 0.0;
      H(k, k) = d;
      H(k + 1, k) = 0;
      g[k + 1] = -sn[k] * g[k];
      g[k] = cs[k] * g[k];
      // The true residual is within the recurrence's plus Σ |z_j| e_j (z: this cycle's solution).
      double bound = 0;
      if (committed.head(k + 1).any()) {
        z = H.topLeftCorner(k + 1, k + 1).triangularView<Eigen::Upper>().solve(g.head(k + 1));
        bound = z.cwiseAbs().dot(committed.head(k + 1));
      }
      res.residual = std::abs(g[k + 1]) + bound;
      if (res.residual <= target || h_next == 0) {  // converged, or the Krylov space is invariant
        done = res.residual <= target;
        ++k;
        break;
      }
      if (bound > 0.5 * target) {  // the committed errors alone use most of the target
        ++res.bound_restarts;
        margin *= 0.25;
        ++k;
        break;
      }
    }
    // x += V z with H z = g (upper triangular k × k).
    z = H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
    for (int j = 0; j < k; ++j) {
      x += z[j] * V[static_cast<size_t>(j)];
      if (aux) *aux += z[j] * W[static_cast<size_t>(j)];
    }
    if (done) {
      res.converged = true;
      return res;
    }
    if (res.iterations >= opt.max_iterations) return res;
  }
}

}  // namespace capsflow
