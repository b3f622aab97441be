#include "capsflow/core/bie/viscosity_ratio.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

namespace capsflow {

namespace {

using Eigen::VectorXd;

// The six rigid-body motions on the nodes, orthonormal in ⟨a, b⟩ = Σ m_i a_i·b_i (columns of Q).
Eigen::Matrix<double, Eigen::Dynamic, 6> rigid_modes(const Points& x, const Eigen::VectorXd& m) {
  const Eigen::Index n = x.rows();
  const Vec3 c = (x.transpose() * m) / m.sum();  // area centroid: the rotations about it
  Eigen::Matrix<double, Eigen::Dynamic, 6> Q(3 * n, 6);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Vec3 r = x.row(i).transpose() - c;
    for (int k = 0; k < 3; ++k) {
      Q.block<3, 1>(3 * i, k) = Vec3::Unit(k);
      Q.block<3, 1>(3 * i, 3 + k) = Vec3::Unit(k).cross(r);
    }
  }
  VectorXd w(3 * n);
  for (Eigen::Index i = 0; i < n; ++i) w.segment<3>(3 * i).setConstant(m[i]);
  for (int k = 0; k < 6; ++k) {  // modified Gram–Schmidt, twice for round-off
    for (int pass = 0; pass < 2; ++pass)
      for (int j = 0; j < k; ++j) Q.col(k) -= (w.array() * Q.col(j).array() * Q.col(k).array()).sum() * Q.col(j);
    Q.col(k) /= std::sqrt((w.array() * Q.col(k).array().square()).sum());
  }
  return Q;
}

Eigen::Map<const VectorXd> flat(const Points& p) { return {p.data(), p.size()}; }

}  // namespace

ViscosityRatioSolver::ViscosityRatioSolver(const Triangles& triangles, Eigen::Index n_nodes, double lambda,
                                           const DoubleLayerOptions& dl_options, const GmresOptions& gmres_options)
    : lambda_(lambda), kappa_((1 - lambda) / (1 + lambda)), D_(triangles, n_nodes, dl_options), gmres_(gmres_options) {
  if (!(lambda > 0) || !std::isfinite(lambda)) throw std::invalid_argument("viscosity ratio: λ must be finite and > 0");
}

// The second-kind system's parts that depend on the surface only: the inner product's weights
// (nodal areas |a_i|, three per node), the orthonormal rigid modes Q with the projection P onto
// them, and the unit normals n̂ with aᵀn̂ (Ã's rank-one term).
struct ViscosityRatioSolver::System {
  System(const Points& x, const Points& area_vectors) : n(x.rows()), a(area_vectors) {
    const VectorXd m = a.rowwise().norm();  // nodal areas (|a_i| = |Σ A_e n_e/3|)
    w.resize(3 * n);
    for (Eigen::Index i = 0; i < n; ++i) w.segment<3>(3 * i).setConstant(m[i]);
    Q = rigid_modes(x, m);
    nhat = a;
    for (Eigen::Index i = 0; i < n; ++i) nhat.row(i) /= m[i];
    a_nhat = m.sum();
  }
  VectorXd project(const VectorXd& v) const { return Q * (Q.transpose() * w.cwiseProduct(v)); }
  double norm(const VectorXd& v) const { return std::sqrt(w.dot(v.cwiseProduct(v))); }

  Eigen::Index n;
  const Points& a;
  VectorXd w;
  Eigen::Matrix<double, Eigen::Dynamic, 6> Q;
  Points nhat;
  double a_nhat;
};

ViscosityRatioStats ViscosityRatioSolver::solve(const Points& x, const Points& a, const Points& v1, Points& u, bool probe,
                                                bool on_trajectory, const Prediction& prediction) {
  const Eigen::Index n = x.rows();
  if (a.rows() != n || v1.rows() != n) throw std::invalid_argument("viscosity ratio: one row per node");
  const System s(x, a);
  // 1 + κ = 2/(1 + λ) and κ/(1 + κ) = (1 − λ)/2, each formed without cancellation.
  const double one_plus_kappa = 2 / (1 + lambda_), kappa_over = (1 - lambda_) / 2;
  const VectorXd v = flat(v1), Pv = s.project(v);
  const VectorXd b = one_plus_kappa * (v - Pv);
  const double v_norm = s.norm(v);
  ViscosityRatioStats st;
  u.resize(n, 3);
  const bool warm = have_previous_ && previous_y_.size() == 3 * n;
  const int slots = Prediction::kSlots;
  if (!probe && prediction.keep_start >= 0 && prediction.keep_start < slots) {
    kept_y_[prediction.keep_start] = warm ? previous_y_ : VectorXd();  // no previous solution: an empty slot
    kept_b_[prediction.keep_start] = warm ? previous_b_ : VectorXd();
  }
  if (v_norm == 0) {  // no flow, no load: u = 0 (the next solve sets the surface up)
    u.setZero();
    if (!probe) remember(VectorXd::Zero(3 * n), VectorXd::Zero(3 * n), VectorXd::Zero(3 * n), true, prediction);
    return st;
  }
  bool predicted = false;
  VectorXd y = initial_guess(s, b, probe, prediction, warm, predicted);
  VectorXd Ay = VectorXd::Zero(3 * n);
  const GmresResult r = iterate(x, s, b, y, v_norm, probe, warm, on_trajectory, Ay);
  st.iterations = r.iterations;
  st.residual = r.residual / (one_plus_kappa * v_norm);  // relative to the solution's scale in both modes
  st.initial_residual = r.initial_residual / (one_plus_kappa * v_norm);
  st.converged = r.converged;
  st.predicted = predicted;
  const VectorXd PAy = s.project(Ay);
  const VectorXd sol = Pv - kappa_over * PAy + y;
  Eigen::Map<VectorXd>(u.data(), u.size()) = sol;
  // b − R y from the iterates' Ã y (GMRES's own residual, the inexact steps' errors included).
  if (!probe) remember(y, b, b - y - kappa_ * (Ay - PAy), r.converged, prediction);
  ++solves_;
  total_iterations_ += r.iterations;
  bound_restarts_ += r.bound_restarts;
  max_iterations_seen_ = std::max(max_iterations_seen_, r.iterations);
  return st;
}

VectorXd ViscosityRatioSolver::initial_guess(const System& s, const VectorXd& b, bool probe, const Prediction& prediction,
                                             bool warm, bool& predicted) const {
  predicted = !probe && prediction.terms > 0 && prediction.terms <= Prediction::kTerms;
  for (int k = 0; predicted && k < prediction.terms; ++k) {
    const int slot = prediction.slot[k];
    predicted = slot >= 0 && slot < Prediction::kSlots && kept_y_[slot].size() == 3 * s.n;
  }
  VectorXd y = b;
  if (predicted) {  // the stages' combination of kept solutions, moved by the change of b likewise
    for (int k = 0; k < prediction.terms; ++k) {
      const int slot = prediction.slot[k];
      y += prediction.weight[k] * (kept_y_[slot] - kept_b_[slot]);
    }
    y -= s.project(y);
  } else if (warm) {  // the previous solution, moved by the change of the right-hand side (R ≈ I)
    y = previous_y_ + (b - previous_b_);
    y -= s.project(y);
  }
  return y;
}

GmresResult ViscosityRatioSolver::iterate(const Points& x, const System& s, const VectorXd& b, VectorXd& y, double v_norm,
                                          bool probe, bool warm, bool on_trajectory, VectorXd& Ay) {
  const Eigen::Index n = s.n;
  const double kappa = kappa_;
  Points Y(n, 3), DY, Y0(n, 3), DY0;
  Eigen::Map<VectorXd>(Y0.data(), Y0.size()) = y;
  D_.set_surface(x, &Y0, &DY0, on_trajectory && !probe);
  // y ↦ R y = y + κ (I − P) Ã y, with aux = Ã y = A y + n̂ (aᵀy)/(aᵀn̂) (y has no rigid part).
  // GMRES applies R to its initial guess first: D_h of it came with the double layer's set-up.
  // R's error is |κ| ≤ 1 times (I − P)Ã's (P is orthogonal in the weighted norm), and Ã = 2 D + an
  // exact rank-one term: D may err by half the allowance, and R commits 2|κ| times D's bound (Ã y,
  // the aux image, twice D's).
  const GmresOperator R = [&](const VectorXd& z, VectorXd& Rz, VectorXd* aux, double allowed_error) {
    Eigen::Map<VectorXd>(Y.data(), Y.size()) = z;
    double committed = 0;
    if (Y0.size() > 0 && Y == Y0) {
      DY = DY0;
      Y0.resize(0, 3);  // used once
    } else {
      committed = D_.apply(Y, DY, 0.5 * allowed_error);
    }
    VectorXd Az = 2.0 * flat(DY) + flat(s.nhat) * (flat(s.a).dot(z) / s.a_nhat);
    Rz = z + kappa * (Az - s.project(Az));
    if (aux) *aux = std::move(Az);
    return 2 * std::abs(kappa) * committed;
  };
  GmresOptions go = gmres_;
  double scale = (2 / (1 + lambda_)) * v_norm;
  VectorXd rhs;
  const bool base = probe && warm && previous_residual_.size() == 3 * n;
  if (base) {
    // The difference from the base: R y = b − r_base, so that y − y_base carries no part of the
    // base's residual; to kProbeAccuracy of the change of b, but not below 1e-3 of the
    // trajectory's target, which the operator's own rounding could not meet.
    rhs = b - previous_residual_;
    go.tolerance = kProbeAccuracy;
    go.floor = 1e-3 * gmres_.tolerance * scale;
    scale = s.norm(b - previous_b_);
  }
  return gmres(R, base ? rhs : b, y, s.w, scale, go, &Ay);
}

void ViscosityRatioSolver::remember(const VectorXd& y, const VectorXd& b, const VectorXd& residual, bool converged,
                                    const Prediction& prediction) {
  previous_y_ = y, previous_b_ = b, previous_residual_ = residual, have_previous_ = true;
  if (prediction.keep >= 0 && prediction.keep < Prediction::kSlots) {
    kept_y_[prediction.keep] = converged ? y : VectorXd();
    kept_b_[prediction.keep] = converged ? b : VectorXd();
  }
}

}  // namespace capsflow
