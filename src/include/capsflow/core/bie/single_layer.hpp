#pragma once
// The single-layer Stokeslet operator on the capsule surface (paper Eq. 34, docs/boundary-integral.md):
//
//   u(x) = (1/8πμ) ∫_S G(x − y)·q(y) dS_y,   G(r) = I/|r| + r rᵀ/|r|³,  r = x − y,  μ = 1,
//
// for a P1 load q on the P1 triangulation; the node velocity is v = v∞ − u. The surface is either
// the flat facets (the paper's discretisation) or their quadratic lift through normal-based edge
// midpoints (geometry "curved", curved_triangle.hpp: O(h³) geometry instead of O(h²)); the load is
// linear in the element's parameters either way. Discretisation at node x_i:
//   far field  — the 3 interior Gauss points of every element as point sources, f_g = w_g q(y_g)
//                with w_g = J(y_g)/6 (= A_e/3 on a flat facet),
//                summed by capsflow::fmm (FMM or direct; both compute the same sum);
//   near field — for the elements touching x_i, the point-source contribution is replaced by the
//                exact integral (Duffy, singular_element_integral); for the next ring of
//                elements, by a refined rule (the 3-point rule's O(h) error comes from them).
// Both back ends therefore compute the same discrete operator, to the FMM tolerance.
// Nodal point sources are never used (O(h) error, docs/boundary-integral.md §4.2.1).
#include <memory>
#include <string>
#include <vector>

#include "capsflow/core/bie/backend_choice.hpp"
#include "capsflow/core/bie/quadrature.hpp"
#include "capsflow/core/phase_times.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {
namespace fmm {
struct Stokeslet;
template <class K>
class Fmm;
}  // namespace fmm
struct OffSurfaceReport;

struct SingleLayerOptions {
  BackendRequest backend = BackendRequest::Auto;
  double tolerance = 1e-6;       // far-field relative accuracy: the FMM order; direct sums use
                                 // single-precision pairs (~5e-7) from 1e-5 on, double below
  SurfaceGeometry geometry = SurfaceGeometry::Flat;  // see above
  // Touching elements: the flat facet is integrated in closed form; a curved element adds its
  // curvature correction by Duffy quadrature with these Gauss–Legendre points (quadrature.hpp).
  int singular_points = 4;          // in v, on each side of the foot v*
  int singular_radial_points = 3;   // in u (at most 16)
  int near_ring_depth = 0;       // near ring (elements sharing a vertex with the touching ones):
                                 // refined 7-point rule on 4^depth parts; -1 disables the ring
  int near_ring_layers = 0;      // edge hops of the ring beyond the touching elements; 0 = auto: 1 for
                                 // flat (the O(h²) geometry error dominates), 2 for curved (the far
                                 // field's O(h) 3-point quadrature error would otherwise dominate)
  int threads = 0;               // 0 = OpenMP default
  int fmm_order = 0;             // > 0 forces the FMM order instead of the one the tolerance calls for
  // > 0: on every verify_every-th apply() (the first one included) the far field is summed again
  // directly, in full double precision, on the same sources and targets (far_field_check()).
  int verify_every = 0;
};

// The far field of one apply() against its direct re-summation: the largest and the RMS node
// difference, both relative to the largest directly summed far-field velocity.
struct FarFieldCheck {
  long evaluation = 0;  // which apply() (0-based, counted by this operator)
  double max_relative = 0, rms_relative = 0;
};


class SingleLayer {
 public:
  SingleLayer(const Triangles& triangles, Eigen::Index n_nodes, const SingleLayerOptions& opt = {});
  ~SingleLayer();
  SingleLayer(const SingleLayer&) = delete;
  SingleLayer& operator=(const SingleLayer&) = delete;

  // u_i at every node x_i (u is resized to N×3).
  void apply(const Points& x, const Points& q, Points& u);

  FarFieldBackend backend() const { return backend_; }
  const std::string& backend_reason() const { return reason_; }
  int fmm_order() const;
  // Seconds in the phases BieSources, BieFar and BieNear, summed over apply() calls.
  const PhaseTimes& times() const { return times_; }
  long evaluations() const { return evaluations_; }
  // Direct checks made so far (SingleLayerOptions::verify_every): how many, the latest, the one
  // with the largest max difference, the largest RMS, and how many exceeded the tolerance.
  long far_field_checks() const { return checks_; }
  const FarFieldCheck& last_far_field_check() const { return last_check_; }
  const FarFieldCheck& worst_far_field_check() const { return worst_check_; }
  double worst_far_field_rms() const { return worst_rms_; }
  long far_field_checks_above_tolerance() const { return checks_above_; }

 private:
  void build_surface(const Points& x);  // vertex normals and edge midpoints of the current surface
  QuadraticTriangle element(const Points& x, Eigen::Index e, int first) const;  // written about vertex `first`
  void build_sources(const Points& x, const Points& q);
  void far_field(const double* targets, Eigen::Index n_targets, double* out, bool targets_are_nodes);
  void correct_touching_elements(const Points& x, const Points& q, Points& u);
  void check_far_field(const Points& x, const Points& far);  // far: the far field just summed

  Triangles tri_;
  Eigen::Index n_nodes_;
  SingleLayerOptions opt_;
  FarFieldBackend backend_;
  std::string reason_;
  bool curved_;
  bool mixed_precision_ = false;  // direct far field with single-precision pairs (tolerance >= 1e-5)
  GaussLegendre rule_, rule_u_;
  Points normals_;                                 // vertex normals (curved only)
  std::vector<Vec3> mid_;                          // edge midpoints: mid_[3e + k] on edge (k, k+1)
  std::vector<StokesletBatch> batches_;            // one per thread, reused across calls
  std::vector<int> node_elem_start_, node_elem_;  // CSR: elements touching each node
  std::vector<int> ring_start_, ring_;             // CSR: next ring of elements around each node
  std::vector<double> src_, strength_;             // Gauss points and strengths (xyz interleaved)
  std::vector<double> ring_src_, ring_strength_;   // 7-point rule of every element (near ring)
  std::unique_ptr<fmm::Fmm<fmm::Stokeslet>> fmm_;
  PhaseTimes times_;
  long evaluations_ = 0;
  long checks_ = 0, checks_above_ = 0;
  FarFieldCheck last_check_, worst_check_;
  double worst_rms_ = 0;
  std::vector<double> direct_scratch_;  // the direct re-summation (allocated on the first check)

  // Off-surface evaluation reuses the sources and far field of the current surface.
  friend void evaluate_off_surface(SingleLayer&, const Points&, const Points&, const Points&, Points&, OffSurfaceReport*);
};

}  // namespace capsflow
