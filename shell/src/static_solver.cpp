#include "capsflow/shell/static_solver.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "capsflow/shell/director.hpp"
#include "capsflow/shell/element_ad.hpp"

namespace capsflow::shell {

struct StaticShell::Impl {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
};

StaticShell::StaticShell(const Points& X, const Triangles& tri, const Points& D_ref, MembraneLaw law,
                         double h, double nu)
    : X_(X), x_(X), law_(law), topo_(tri, X.rows()), impl_(std::make_shared<Impl>()) {
  const int n = topo_.n_nodes;
  triads_ = NodalTriads(D_ref.rows() == n ? D_ref : area_weighted_normals(X, tri));
  const Points& d = triads_.d;
  ref_.resize(topo_.n_elems);
  for (int e = 0; e < topo_.n_elems; ++e) {
    const auto& t = topo_.tri[e];
    const Vec3 Xe[3] = {X.row(t[0]), X.row(t[1]), X.row(t[2])};
    const Vec3 De[3] = {d.row(t[0]), d.row(t[1]), d.row(t[2])};
    ref_[e] = make_element_ref(Xe, De, t, h, law.Gs() / h, nu);
  }
  fixed_.assign(5 * n, 0);
  theta_acc_.setZero(n, 3);
  F_.setZero(n, 3);
  M_.setZero(n, 3);
}

void StaticShell::fix_translation(int node, int comp) { fixed_[5 * node + comp] = 1; }

void StaticShell::fix_rotations(int node) { fixed_[5 * node + 3] = fixed_[5 * node + 4] = 1; }

void StaticShell::fix_rotation_about(int node, const Vec3& axis) {
  const Vec3 d = triads_.d.row(node);
  const Vec3 a = axis - axis.dot(d) * d;
  if (a.norm() < 1e-12 * axis.norm()) return;  // axis along the director: no (drilling) DOF
  if (fixed_[5 * node + 3]) {                  // second independent axis: clamp
    const Vec3 t1 = triads_.t1.row(node);
    if (std::abs(a.normalized().dot(t1)) < 1 - 1e-12) fixed_[5 * node + 4] = 1;
    return;
  }
  const Vec3 t1 = a.normalized();
  triads_.t1.row(node) = t1;
  triads_.t2.row(node) = d.cross(t1);
  fixed_[5 * node + 3] = 1;  // w1 = omega . t1 = 0
}

void StaticShell::assemble(double lambda, bool want_K) {
  const int n = topo_.n_nodes;
  r_.setZero(5 * n);
  fext_.setZero(5 * n);
  for (int i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) fext_[5 * i + c] = lambda * F_(i, c);
    const Vec3 m = M_.row(i);
    fext_[5 * i + 3] = lambda * m.dot(Vec3(triads_.t1.row(i)));
    fext_[5 * i + 4] = lambda * m.dot(Vec3(triads_.t2.row(i)));
  }
  trip_.clear();
  if (want_K) trip_.reserve(static_cast<size_t>(topo_.n_elems) * 225 + 5 * n);
  std::vector<ElementHessian> eh(topo_.n_elems);
#pragma omp parallel for schedule(static)
  for (int e = 0; e < topo_.n_elems; ++e) {
    const auto& nd = ref_[e].m.n;
    Vec3 xe[3], de[3], a[3], b[3];
    for (int k = 0; k < 3; ++k) {
      xe[k] = x_.row(nd[k]);
      de[k] = triads_.d.row(nd[k]);
      a[k] = triads_.t1.row(nd[k]);
      b[k] = triads_.t2.row(nd[k]);
    }
    element_hessian(ref_[e], law_, xe, de, a, b, eh[e]);
  }
  auto dof = [&](int e, int l) {  // local dof l (0..14) -> global
    const auto& nd = ref_[e].m.n;
    return l < 9 ? 5 * nd[l / 3] + l % 3 : 5 * nd[(l - 9) / 2] + 3 + (l - 9) % 2;
  };
  for (int e = 0; e < topo_.n_elems; ++e) {
    for (int l = 0; l < 15; ++l) r_[dof(e, l)] += eh[e].g[l];
    if (!want_K) continue;
    for (int l = 0; l < 15; ++l) {
      const int I = dof(e, l);
      if (fixed_[I]) continue;
      for (int k = 0; k < 15; ++k) {
        const int J = dof(e, k);
        if (!fixed_[J]) trip_.emplace_back(I, J, eh[e].H[l][k]);  // keep zeros: fixed pattern
      }
    }
  }
  r_ -= fext_;
  for (int I = 0; I < 5 * n; ++I)
    if (fixed_[I]) {
      r_[I] = 0;
      fext_[I] = 0;
      if (want_K) trip_.emplace_back(I, I, 1.0);
    }
  if (want_K) {
    K_.resize(5 * n, 5 * n);
    K_.setFromTriplets(trip_.begin(), trip_.end());
  }
}

double StaticShell::potential(double lambda) const {
  double E = 0;
#pragma omp parallel for schedule(static) reduction(+ : E)
  for (int e = 0; e < topo_.n_elems; ++e) {
    const auto& nd = ref_[e].m.n;
    double xe[3][3], de[3][3], out[3];
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) {
        xe[k][c] = x_(nd[k], c);
        de[k][c] = triads_.d(nd[k], c);
      }
    element_energy_t<double>(ref_[e], law_, xe, de, out);
    E += out[0] + out[1] + out[2];
  }
  double W = 0;
  for (int i = 0; i < topo_.n_nodes; ++i)
    W += F_.row(i).dot(x_.row(i) - X_.row(i)) + M_.row(i).dot(theta_acc_.row(i));
  return E - lambda * W;
}

void StaticShell::apply_increment(const Eigen::VectorXd& du, double alpha) {
  for (int i = 0; i < topo_.n_nodes; ++i) {
    for (int c = 0; c < 3; ++c) x_(i, c) += alpha * du[5 * i + c];
    const Vec3 om = alpha * (du[5 * i + 3] * Vec3(triads_.t1.row(i)) + du[5 * i + 4] * Vec3(triads_.t2.row(i)));
    triads_.rotate(i, om);
    theta_acc_.row(i) += om.transpose();
  }
}

StaticStep StaticShell::newton(double lambda, const StaticOptions& opt) {
  StaticStep st;
  st.load_factor = lambda;
  const int n = topo_.n_nodes;
  double prev = 1e300;
  for (int it = 0;; ++it) {
    assemble(lambda, true);
    const double fn = std::max(fext_.norm(), 1e-300);
    st.residual = r_.norm() / fn;
    if (it > 0 && (st.residual <= opt.tol ||
                   (st.residual <= opt.floor_tol && st.residual > 0.5 * prev))) {
      st.converged = true;  // below tol, or stagnating at the round-off floor below floor_tol
      break;
    }
    prev = st.residual;
    if (it >= opt.max_newton) break;
    Eigen::VectorXd du;
    if (opt.use_cg) {
      Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                               Eigen::IncompleteCholesky<double>>
          cg;
      cg.setTolerance(opt.cg_tol);
      cg.setMaxIterations(100000);
      cg.compute(K_);
      du = cg.solve(-r_);
    } else {
      if (!analysed_) {
        impl_->ldlt.analyzePattern(K_);
        analysed_ = true;
      }
      impl_->ldlt.factorize(K_);
      if (impl_->ldlt.info() != Eigen::Success) throw std::runtime_error("StaticShell: factorisation failed");
      du = impl_->ldlt.solve(-r_);
    }
    // damping: largest nodal rotation per iteration <= max_rotation
    double big = 0;
    for (int i = 0; i < n; ++i) big = std::max(big, std::hypot(du[5 * i + 3], du[5 * i + 4]));
    double alpha = big > opt.max_rotation ? opt.max_rotation / big : 1.0;
    // backtracking (Armijo) on the total potential when du is a descent direction
    const double slope = r_.dot(du);
    if (opt.line_search && slope < 0) {
      const Points x0 = x_, th0 = theta_acc_;
      const NodalTriads triads0 = triads_;
      const double P0 = potential(lambda);
      for (int ls = 0; ls < 12; ++ls) {
        apply_increment(du, alpha);
        if (potential(lambda) <= P0 + 1e-4 * alpha * slope) break;
        x_ = x0;
        triads_ = triads0;
        theta_acc_ = th0;
        alpha *= 0.5;
        if (ls == 11) apply_increment(du, alpha);
      }
    } else {
      apply_increment(du, alpha);
    }
    ++st.newton;
  }
  return st;
}

StaticStep StaticShell::solve_linear(const StaticOptions& opt) {
  StaticOptions o = opt;
  o.max_newton = 1;
  o.max_rotation = std::numeric_limits<double>::infinity();  // the linear solution, undamped
  o.line_search = false;
  StaticStep st = newton(1.0, o);
  st.converged = true;  // by definition: one linear solve
  return st;
}

}  // namespace capsflow::shell
