#pragma once
// The surface velocity of a capsule whose inner liquid is λ times as viscous as the outer one
// (docs/boundary-integral.md §4.8): the second-kind boundary integral equation
//
//   (1 + λ)/2 u + (1 − λ) D[u] = v1,   v1 = v∞ − S[q]  (the velocity the capsule would have at λ = 1),
//
// with D the double layer of double_layer.hpp (D[c] = c/2), written as
//   u + κ A u = (1 + κ) v1,   A = 2D,   κ = (1 − λ)/(1 + λ) ∈ (−1, 1).
// A has the eigenvalue 1 on the six rigid-body motions and −1 on the mode whose left eigenvector is
// the normal (the volume mode), so the equation degenerates as λ → ∞ and λ → 0. Both are deflated:
// with P the projector on the rigid motions (orthogonal in the nodal-area inner product) and
// a_i = ∂V/∂x_i the discrete flux weights,
//   Ã = A (I − P) + P + n̂ aᵀ/(aᵀn̂),   n̂_i = a_i/|a_i|,
// has the rigid motions as exact eigenvectors (eigenvalue 1, as A has them in the continuum) and
// eigenvalue ≈ 0 on the volume mode. Splitting u = P u + y, the equation (I + κÃ) u = (1 + κ) v1 is
// block-triangular:
//   y + κ (I − P) Ã y = (1 + κ)(I − P) v1          (GMRES; spectrum 1 + κμ, |μ| ≤ 3/5 on a sphere)
//   P u = P v1 − κ/(1 + κ) · P Ã y                   (no solve; Ã y comes with the GMRES iterates)
// so that neither limit is ill-conditioned and the rigid-body velocity is not amplified by λ.
// The flux of u is (1 + κ) times that of v1 (in the continuum both vanish).
//
// GMRES starts from the last trajectory solve's y plus the change of the right-hand side since
// (R is close to I; docs/boundary-integral.md §4.8.3) — or, inside a step whose stages are
// combinations of earlier ones (Prediction), from the same combination of their solutions, moved
// likewise — and stops when the residual is below
// tolerance × (1 + κ) ‖v1‖ (nodal-area RMS): the error in u is then about tolerance × ‖v1‖.
// A probe (a point off the trajectory, y + δw of the spectral-radius power iteration, which
// differences its velocity against the last solve's, δ apart) solves for that difference only: it
// takes the base's final residual into its right-hand side, so that the base's own solver error
// cancels in the difference, and stops when the residual is below kProbeAccuracy × the change of
// the right-hand side (docs/boundary-integral.md §4.8.3); it leaves the warm start alone. Its
// velocity is meant for that difference: on its own it carries the base's error.
#include <array>

#include "capsflow/core/bie/double_layer.hpp"
#include "capsflow/core/bie/gmres.hpp"

namespace capsflow {

struct ViscosityRatioStats {
  int iterations = 0;    // double-layer applications by GMRES in the last solve
  double residual = 0;   // its final residual relative to (1 + κ)‖v1‖
  double initial_residual = 0;  // its initial guess's, likewise
  bool converged = true;
  bool predicted = false;  // started from a Prediction's combination of kept solutions
};

// A probe's accuracy, relative to the change of its right-hand side from the base's: the power
// iteration stops when σ changes by 1 % (spectral_radius.hpp), which a 1e-3 error in each
// difference leaves intact.
inline constexpr double kProbeAccuracy = 1e-3;

// The warm start across the stages of a step (the time stepper's stage predictor, handed on by
// the right-hand side; docs/boundary-integral.md §4.8.3): before solving, keep_start keeps the
// last trajectory solve's solution in that slot; after a converged solve, keep keeps this one's;
// terms > 0 says this surface's state ≈ Σ weight_k × (the state solved in slot_k), Σ weight = 1,
// and GMRES starts from Σ weight_k y_k moved by b − Σ weight_k b_k (R ≈ I).
struct ViscosityRatioPrediction {
  static constexpr int kSlots = 4, kTerms = 4;
  int keep_start = -1, keep = -1, terms = 0;
  std::array<int, kTerms> slot{};
  std::array<double, kTerms> weight{};
};

class ViscosityRatioSolver {
 public:
  ViscosityRatioSolver(const Triangles& triangles, Eigen::Index n_nodes, double lambda,
                       const DoubleLayerOptions& dl_options, const GmresOptions& gmres_options);

  using Prediction = ViscosityRatioPrediction;

  // u on the surface x for the λ = 1 velocity v1; a = ∂V/∂x_i (volume_gradient). Returns the
  // statistics of the solve; u is written also when it did not converge. on_trajectory = false
  // (a probe, or an output between steps) leaves the double layer's reused terms alone.
  ViscosityRatioStats solve(const Points& x, const Points& a, const Points& v1, Points& u, bool probe = false,
                            bool on_trajectory = true, const Prediction& prediction = {});

  double lambda() const { return lambda_; }
  double kappa() const { return kappa_; }
  const DoubleLayer& double_layer() const { return D_; }
  long solves() const { return solves_; }
  long total_iterations() const { return total_iterations_; }
  int max_iterations_seen() const { return max_iterations_seen_; }
  // GMRES cycles ended because the inexact steps' committed errors alone reached half the target
  // (gmres.hpp): each costs an exact application; none is the expected case.
  long bound_restarts() const { return bound_restarts_; }
  // The next trajectory solve's warm start, to put back after a solve off the trajectory (an
  // output between two steps). With D̃[1]'s reuse records (DoubleLayer::identity_records) it is all
  // that a trajectory solve carries to the next: a checkpoint keeps both
  // (CapsuleDynamics::save_fluid_state), so that a restarted run continues bit for bit.
  struct WarmStart {
    Eigen::VectorXd y, b, residual;
    bool valid = false;
  };
  WarmStart warm_start() const { return {previous_y_, previous_b_, previous_residual_, have_previous_}; }
  void set_warm_start(WarmStart w) {
    previous_y_ = std::move(w.y), previous_b_ = std::move(w.b), previous_residual_ = std::move(w.residual);
    have_previous_ = w.valid;
  }
  bool set_identity_records(const std::vector<double>& records, int count) { return D_.set_identity_records(records, count); }

 private:
  struct System;  // one surface's weights, rigid modes and normals (viscosity_ratio.cpp)
  // Where GMRES starts: the stages' combination of kept solutions (`predicted`), else the previous
  // solution moved by the change of b, else b; without rigid part.
  Eigen::VectorXd initial_guess(const System& s, const Eigen::VectorXd& b, bool probe, const Prediction& prediction,
                                bool warm, bool& predicted) const;
  // Sets the double layer up on x (with D_h of y from the same pass) and iterates R y = b from y;
  // a probe with a base solves for the difference from it. Ay: Ã y of the last iterate.
  GmresResult iterate(const Points& x, const System& s, const Eigen::VectorXd& b, Eigen::VectorXd& y, double v_norm,
                      bool probe, bool warm, bool on_trajectory, Eigen::VectorXd& Ay);
  // The trajectory's records after a solve: the warm start and the stage predictor's slot.
  void remember(const Eigen::VectorXd& y, const Eigen::VectorXd& b, const Eigen::VectorXd& residual, bool converged,
                const Prediction& prediction);

  double lambda_, kappa_;
  DoubleLayer D_;
  GmresOptions gmres_;
  // The last solve that was not a probe: its solution, right-hand side and final residual b − R y
  // (the probes' base, which they are differenced against).
  Eigen::VectorXd previous_y_, previous_b_, previous_residual_;
  bool have_previous_ = false;
  std::array<Eigen::VectorXd, Prediction::kSlots> kept_y_, kept_b_;  // the stages' solutions (Prediction)
  long solves_ = 0, total_iterations_ = 0, bound_restarts_ = 0;
  int max_iterations_seen_ = 0;
};

}  // namespace capsflow
