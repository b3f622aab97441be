#pragma once
// The single-layer Stokeslet operator on the capsule surface (paper Eq. 34, docs/boundary-integral.md):
//
//   u(x) = (1/8πμ) ∫_S G(x − y)·q(y) dS_y,   G(r) = I/|r| + r rᵀ/|r|³,  r = x − y,  μ = 1,
//
// for a P1 load q on the P1 triangulation; the node velocity is v = v∞ − u. The surface is either
// the flat facets (the paper's discretisation) or their quadratic lift through normal-based edge
// midpoints (geometry "curved", curved_triangle.hpp: O(h³) geometry instead of O(h²)); the load is
// linear in the element's parameters either way. Discretisation at node x_i:
//   far field  — a degree-2 rule on every element, its points as point sources summed by
//                capsflow::fmm (FMM or direct; the same sum), with weights w = J/6 (= A_e/3 when
//                flat): on flat facets the edge-midpoint rule, whose points the two elements of an
//                edge share (one source per edge: 3N sources for N nodes); on curved elements the
//                3-point Gauss rule (6N), whose smaller error their O(h⁴) geometry needs
//                (far_field.hpp: the same component sums the double layer's far field);
//   near field — on the elements near x_i (near_field.hpp) the far-field contributions are
//                replaced: by the exact integral on the touching elements (singular_element_integral),
//                a refined rule on the next ring, the 3-point Gauss rule on a band beyond it.
// Both back ends therefore compute the same discrete operator, to the FMM tolerance. Vertex
// (nodal) sources would be N, but their error is of the size of the faceting error however wide
// the corrected region (docs/boundary-integral.md §4.2.1).
#include <string>
#include <vector>

#include "capsflow/core/bie/boundary_surface.hpp"
#include "capsflow/core/bie/far_field.hpp"
#include "capsflow/core/bie/layer_options.hpp"
#include "capsflow/core/bie/near_field.hpp"
#include "capsflow/core/bie/quadrature.hpp"
#include "capsflow/core/bie/stokeslet_block.hpp"
#include "capsflow/core/phase_times.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {
namespace fmm {
struct Stokeslet;
}  // namespace fmm
struct OffSurfaceReport;

// The single layer's options: those both layers share (layer_options.hpp), and the refined ring.
struct SingleLayerOptions : LayerOptions {
  // Not a scene key (perf/bie/bie_bench varies it, to measure the ring's rule against its cost):
  // the near ring (elements sharing a vertex with the touching ones) by the 7-point rule on
  // 4^depth parts, computed per node; 0: the 7-point rule once per element; −1: no ring.
  int near_ring_depth = 0;
};

// The automatic corrected_layers with the edge-midpoint far field (docs/boundary-integral.md
// §4.2.2: from there on the midpoint rule is as accurate as the 3-point far field it replaced).
inline constexpr int kAutoCorrectedLayers = 3;

class SingleLayer {
 public:
  SingleLayer(const Triangles& triangles, Eigen::Index n_nodes, const SingleLayerOptions& opt = {});
  ~SingleLayer();
  SingleLayer(const SingleLayer&) = delete;
  SingleLayer& operator=(const SingleLayer&) = delete;

  // u_i at every node x_i (u is resized to N×3).
  void apply(const Points& x, const Points& q, Points& u);

  // The surface of the last apply(), and what its far field summed for element e at a point p
  // (its rule points' Stokeslets, unscaled; a pair at r = 0 skipped as the far field skips it): a
  // near-field correction at a target off this element's surface subtracts exactly this.
  const Triangles& triangles() const { return tri_; }
  const BoundarySurface& surface() const { return surface_; }
  Vec3 element_far_terms(Eigen::Index e, const Vec3& p) const;

  FarFieldBackend backend() const { return far_.backend(); }
  FarFieldRule far_rule() const { return far_.rule(); }
  Eigen::Index far_field_sources() const { return far_.sources(); }
  const NearFieldLists& near_field_lists() const { return lists_; }
  const std::string& backend_reason() const { return far_.reason(); }
  double far_field_tolerance() const { return far_.tolerance(); }  // the back end's promise (far_field.hpp)
  int fmm_order() const { return far_.fmm_order(); }
  int fmm_leaf_size() const { return far_.fmm_leaf_size(); }  // points per leaf of the FMM's tree; 0 with the direct far field
  // Seconds in the phases BieSources, BieFar and BieNear, summed over apply() calls.
  const PhaseTimes& times() const { return times_; }
  long evaluations() const { return evaluations_; }
  // Direct checks of the far field made so far (LayerOptions::verify_every: every verify_every-th
  // apply(), the first one included).
  const FarFieldCheckLog& far_field_checks() const { return far_.checks(); }

 private:
  void build_sources(const Points& x, const Points& q);
  void far_field(double* out, bool at_nodes);  // at far_'s targets: the nodes, or points off the surface
  void correct_near_field(const Points& x, const Points& q, Points& u);

  Triangles tri_;
  Eigen::Index n_nodes_;
  SingleLayerOptions opt_;
  int threads_;                                    // OpenMP threads of every parallel region
  bool mixed_precision_ = false;  // direct far field with single-precision pairs (tolerance >= 1e-5)
  GaussLegendre rule_, rule_u_;
  NearFieldLists lists_;
  BoundarySurface surface_;                        // the flat or curved elements of the current surface
  FarField<fmm::Stokeslet> far_;                   // sources: the load's force at each rule point
  std::vector<StokesletBatch> batches_;            // one per thread, reused across calls
  // Per element, the near field's terms (stokeslet_block.hpp): far_block_ lanes 0–2 the band's
  // 3-point rule, lanes 3–5 the far-field terms negated (exactly the far field's positions);
  // ring_block_ lanes 0–6 the ring's 7-point rule.
  static constexpr int kBandLane = 0, kFarLane = 3;
  std::vector<StokesletBlock> far_block_, ring_block_;
  PhaseTimes times_;
  long evaluations_ = 0;

  // Off-surface evaluation reuses the sources and far field of the current surface.
  friend void evaluate_off_surface(SingleLayer&, const Points&, const Points&, const Points&, Points&, OffSurfaceReport*);
};

}  // namespace capsflow
