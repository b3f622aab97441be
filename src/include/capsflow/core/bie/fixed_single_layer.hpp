#pragma once
// The single layer at the nodes of a surface that does not move (a channel's wall, fixed_wall.hpp):
// the discrete operator of SingleLayer::apply (single_layer.hpp) on flat facets, with everything
// that depends on the geometry alone set up once.
//   near field — at node i, the touching elements' closed-form integrals, the ring's refined rule
//                and the band's 3-point rule, minus the far field's terms of all these elements:
//                linear in the nodal load, so one sparse 3N × 3N matrix, a 3×3 block for every
//                pair of nodes within the corrected layers' reach (~61 blocks per node with the
//                automatic layers; 12 bytes a nonzero);
//   far field  — its sources (the edge midpoints) and targets (the nodes) fixed: each source's
//                force is a fixed weight of the load at its elements' vertices, and the FMM builds
//                its tree, lists and operators on the first evaluation only (far_field.hpp sets it
//                up again only when the sources or targets move).
// An evaluation is a far-field pass plus a sparse mat-vec; the sum is the same as SingleLayer's
// to round-off (the same back end on the same sources: tests/core/bie/test_fixed_wall.cpp).
// Or, within a memory budget (dense_megabytes), the whole operator as one dense 3N × 3N matrix,
// 72 N² bytes (566 MB at 2 804 nodes): the near-field matrix plus every far-field pair summed
// once in double precision (its pairs exact where the direct sum's are within ~1e-9, far_field.hpp),
// and an evaluation one mat-vec that streams it (perf/bie/wall_operator: docs/channel.md §3.2).
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "capsflow/core/bie/boundary_surface.hpp"
#include "capsflow/core/bie/far_field.hpp"
#include "capsflow/core/bie/near_field.hpp"
#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/phase_times.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

using SparseRows = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// The near field of the flat surface (x, t) as a 3N × 3N matrix (scaled by 1/8π: rows 3i..3i+2
// give u_i): the touching elements' closed-form integrals and the ring's refined rule (depth as
// SingleLayerOptions::near_ring_depth, 0 the 7-point rule); with `far`, the far field placed on
// this surface, also the band's 3-point rule and minus far's terms of the touching, ring and band
// elements — the whole correction SingleLayer::apply adds to its far field. Without, the touching
// and ring integrals alone: the fixed wall's preconditioner.
SparseRows near_field_matrix(const Points& x, const Triangles& t, const NearFieldLists& lists, int ring_depth,
                             const FarField<fmm::Stokeslet>* far, int threads);

class FixedSingleLayer {
 public:
  // The surface's flat facets at their fixed positions; throws for curved geometry. The operator
  // is stored dense when its 72 N² bytes are within dense_megabytes (0: never).
  FixedSingleLayer(const SurfaceMesh& surface, const SingleLayerOptions& opt = {}, double dense_megabytes = 0);
  ~FixedSingleLayer();
  FixedSingleLayer(const FixedSingleLayer&) = delete;
  FixedSingleLayer& operator=(const FixedSingleLayer&) = delete;

  // u_i at every node for the load q (u is resized to N×3).
  void apply(const Points& q, Points& u);

  const NearFieldLists& near_field_lists() const { return lists_; }
  FarFieldBackend backend() const { return far_.backend(); }
  bool dense() const { return dense_.size() > 0; }
  double far_field_tolerance() const { return far_.tolerance(); }
  const FarFieldCheckLog& far_field_checks() const { return far_.checks(); }
  // What the stored operator holds: the near-field matrix and the sources' weights, or the dense
  // matrix (the FMM's tree and operators, which SingleLayer keeps as well, are not counted).
  double megabytes() const;
  double setup_seconds() const { return setup_seconds_; }
  // Seconds in BieSources (the sources' forces), BieFar and BieNear, summed over apply() calls.
  const PhaseTimes& times() const { return times_; }
  long evaluations() const { return evaluations_; }

 private:
  void make_dense(const Points& x);  // the near-field matrix and every far-field pair in dense_
  Eigen::Index n_nodes_;
  int threads_;
  bool mixed_precision_ = false;
  NearFieldLists lists_;
  BoundarySurface surface_;
  FarField<fmm::Stokeslet> far_;
  // Per source s, its force from the load: Σ_k weight_[k] q(node_[k]) over k in [start_[s], start_[s+1]).
  std::vector<int> start_, node_;
  std::vector<double> weight_;
  std::vector<double> density_;  // 3 per source
  SparseRows near_;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> dense_;  // 3N × 3N, or empty
  double setup_seconds_ = 0;
  PhaseTimes times_;
  long evaluations_ = 0;
};

}  // namespace capsflow
