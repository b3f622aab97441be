#pragma once
// A fixed closed wall around the flow with a prescribed velocity u_w on it (docs/channel.md §3): the
// side of a channel where u_w = 0 and its end caps where u_w is the inflow and outflow profile.
// For a Stokes flow inside the wall (viscosity 1), Green's identity with the outward normal reads,
// at every point x of the wall — its edges and corners included —
//
//   S[f](x) = −(1/8π) ∫ T(x − y) : (u_w(y) − u_w(x)) n(y) dS_y  =  ½ u_w − D_h[u_w]  (+ what other
//             surfaces in the flow induce on the wall),
//
// for the traction f = σ·n the fluid exerts through the wall, and inside
//
//   u(p) = S[f](p) + D[u_w](p).
//
// (The subtracted form of the double layer is the interior limit at any boundary point, so no
// solid angle enters: docs/boundary-integral.md §4.7.1–4.7.3 for S, D_h and their discretisation.)
// The first-kind equation is singular: S[n] = 0 inside a closed surface (a uniform pressure moves
// nothing), so the traction is defined up to a multiple of n. The solve takes the one with zero
// mean normal traction: GMRES (gmres.hpp) on S[f] + n ⟨n, f⟩/|W|, the nodal-area inner product,
// whose added rank-one term is 1 on n and leaves S untouched on the rest. Preconditioned on the
// right by the wall's near field: M, the single layer of each node's touching and ring elements
// alone (the same closed-form and 7-point integrals as the operator's), carries the operator's
// grid-scale part — what makes a first-kind equation ill-conditioned as h → 0 — and is factored
// once (sparse LU), so that GMRES sees S M⁻¹ (docs/channel.md §3.2: a third fewer iterations).
// The wall does not move, so its operator S is set up once as well (fixed_single_layer.hpp: the
// whole near field one sparse matrix, the far field on fixed sources): an iteration is a sparse
// LU solve, a sparse mat-vec and a far-field pass (docs/channel.md §3.2 for its cost).
#include <array>
#include <memory>
#include <vector>

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include "capsflow/core/bie/double_layer.hpp"
#include "capsflow/core/bie/fixed_single_layer.hpp"
#include "capsflow/core/bie/gmres.hpp"
#include "capsflow/core/bie/off_surface.hpp"
#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

struct FixedWallOptions {
  SingleLayerOptions layer;  // the wall's single layer (and the double layer's back end and surface)
  GmresOptions gmres{1e-8, 60, 2000, 0};  // relative to ‖right-hand side‖ in the nodal-area norm
  bool precondition = true;  // by the near field's sparse LU (above); false: plain GMRES
  // The traction's normal part carried with each element's own normal where it differs from the
  // node's (an edge or a corner of the wall): docs/channel.md §3.5. false: plain P1.
  bool edge_pressure = true;
  double edge_angle = 0.1;  // |n_e − n_k| above which a vertex counts as on an edge (about 6°)
  // S set up once (FixedSingleLayer); false: SingleLayer::apply recomputes the sources, the near
  // field and the far field's set-up at every iteration (the same operator; kept to measure
  // against, perf/bie/wall_operator).
  bool reuse_operator = true;
  // With reuse_operator: the operator stored as one dense matrix where its 72 N² bytes are within
  // this many megabytes (FixedSingleLayer; 0: never). 1000 takes walls up to 3 726 nodes (the
  // default channel's 2 762: 549 MB), where an iteration measured 4–9× faster than recomputing and
  // 4–7× faster than the sparse near field with the direct far field (perf/bie/wall_operator,
  // docs/channel.md §3.2).
  double dense_operator_mb = 1000;
};

struct FixedWallSolve {
  int iterations = 0;
  double residual = 0;          // relative to the right-hand side (or to the velocity scale)
  bool converged = false;
  double seconds = 0;
};

class FixedWall {
 public:
  // wall: the closed surface (outward normals); velocity: u_w at its nodes. Sets up the wall's
  // operators and the right-hand side ½ u_w − D_h[u_w] once (the wall does not move).
  FixedWall(const SurfaceMesh& wall, const Points& velocity, const FixedWallOptions& opt = {});
  ~FixedWall();

  // Solves for the traction with `induced` (the velocity other surfaces induce at the wall's
  // nodes, null for none) added to the right-hand side; warm-started from the last traction. The
  // GMRES tolerance is relative to the right-hand side, or, given a velocity scale > 0 (the flow's),
  // to that scale: a right-hand side that is round-off of the flow's velocity takes no iteration.
  FixedWallSolve solve(const Points* induced = nullptr, double velocity_scale = 0);
  const Points& traction() const { return traction_; }
  // The next solve's warm start (a checkpoint's, or one put back after an output between steps).
  void set_traction(const Points& f);

  // u at points inside the wall: S[f] + D[u_w] (the single layer with the near-surface check of
  // off_surface.hpp; the double layer by adaptive quadrature on the elements where u_w ≠ 0).
  void velocity_at(const Points& targets, Points& u, OffSurfaceReport* report = nullptr);
  // S_W[traction] alone (with the edges' pressure) at points inside the wall, for a traction other
  // than the solved one (e.g. a difference of two solves).
  void single_layer_at(const Points& traction, const Points& targets, Points& u, OffSurfaceReport* report = nullptr);

  // Sf = S[f] at the wall's nodes, by the operator the options chose (no rank-one term).
  void apply(const Points& f, Points& Sf);

  const SurfaceMesh& mesh() const { return mesh_; }
  const Points& velocity() const { return velocity_; }
  const Eigen::VectorXd& nodal_area() const { return area_; }
  const Points& nodal_normal() const { return normal_; }
  bool preconditioned() const { return preconditioned_; }
  // The preconditioner's memory: the near field's blocks and its LU factors, a double and an index
  // per nonzero.
  double preconditioner_megabytes() const;
  // The edges' pressure columns at the wall's nodes (§3.5): 3N × (edge nodes) doubles.
  double edge_pressure_megabytes() const { return static_cast<double>(edge_at_nodes_.size()) * sizeof(double) / 1e6; }
  // The operator set up once (FixedSingleLayer::megabytes); 0 with reuse_operator false.
  double operator_megabytes() const { return op_ ? op_->megabytes() : 0.0; }
  const FixedSingleLayer* fixed_operator() const { return op_.get(); }

 private:
  void build_preconditioner();
  // The single layer of the edge-pressure correction of traction t: on each element with a vertex
  // on an edge, the P1 density Σ_k φ_k (n_e − n_k)(n_k·t_k). At the wall's own nodes it is linear
  // in the edge nodes' pressures n_k·t_k, and the wall does not move: edge_at_nodes_ (3N × edge
  // nodes) is integrated once; at other points (add_edge_pressure) it is integrated each call.
  void build_edge_pressure();
  void add_edge_pressure(const Points& t, const Points& targets, Points& u) const;
  struct EdgeElement {
    Eigen::Index e;
    std::array<Vec3, 3> dn;  // n_e − n_k at its vertices k (zero where below edge_angle)
  };
  std::vector<EdgeElement> edge_elements_;
  std::vector<Eigen::Index> edge_nodes_;  // nodes with a nonzero n_e − n_k on some element
  Eigen::MatrixXd edge_at_nodes_;
  SurfaceMesh mesh_;
  Points velocity_;
  std::vector<Eigen::Index> moving_;  // elements with a non-zero wall velocity at a vertex
  FixedWallOptions opt_;
  std::unique_ptr<SingleLayer> S_;          // velocity_at's (and the iterations' without reuse_operator)
  std::unique_ptr<FixedSingleLayer> op_;    // the iterations' with reuse_operator
  Points rhs0_;       // ½ u_w − D_h[u_w]
  Points traction_;
  Eigen::VectorXd area_, weight_;  // nodal areas; per unknown (3 per node)
  Points normal_;     // unit area-weighted nodal normals
  double total_area_ = 0;
  Eigen::SparseMatrix<double> near_;  // M, 3N × 3N
  Eigen::SparseLU<Eigen::SparseMatrix<double>> near_lu_;
  bool preconditioned_ = false;
};

}  // namespace capsflow
