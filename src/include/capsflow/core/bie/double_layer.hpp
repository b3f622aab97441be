#pragma once
// The double-layer operator on the capsule surface at the nodes (docs/boundary-integral.md §4.7):
//
//   D[u](x) = (1/8π) PV∫_S T(x − y) : u(y) n(y) dS_y,   (T : u n)_i = T_ijk u_j n_k,
//   T_ijk(r) = −6 r_i r_j r_k/|r|⁵,  r = x − y,  n the outward normal,
//
// for a velocity u linear on each element (nodal values u_k), discretised as the single layer
// (single_layer.hpp: the same far-field rule and sources, near-field lists and surface). With this
// sign D[c] = c/2 for a constant c at every smooth point of a closed surface (the Gauss-type
// identity PV∫ T(x − y)·n dS = 4π I). The operator is
//   D_h[u](x_i) = ½ u_i + D̃[u](x_i) − D̃[1](x_i) u_i,
// D̃ the discrete integral and D̃[1](x_i) its value for the three unit constants: the identity is
// imposed exactly (D_h[c] = c/2), which removes the O(h) error of the polyhedral vertices and every
// error proportional to u_i. Its parts:
//   far field  — the single layer's far-field points as stresslet sources (far_field.hpp), summed
//                by the FMM or directly;
//   near field — touching elements (curved ones by Duffy points; flat ones contribute nothing) and
//                the near ring (Dunavant's 7 points), minus their far-field terms; no band unless
//                asked (kAutoDoubleLayerCorrectedLayers): a sparse matrix of symmetric 3×3 blocks
//                per node, and the diagonal ½ I − D̃[1](x_i);
//   D̃[1]      — a far-field pass of the three unit constants plus the near blocks' row sums; on
//                flat facets with the FMM back end, between refreshes, the corner value plus the
//                reused quadrature error (identity_term_cache.hpp: §4.7.5);
//   inexact steps — apply() with an allowed error sums the far field by a cheaper FMM of lower order
//                (or single-precision pairs with the direct back end).
//
// set_surface(x) does everything that depends only on the surface — the far field's points and
// normals, the near-field blocks, D̃[1] — so that the repeated applications of an iterative solve
// (apply(u)) cost one far-field sum and one sparse product each.
#include <memory>
#include <string>
#include <vector>

#include "capsflow/core/bie/boundary_surface.hpp"
#include "capsflow/core/bie/far_field.hpp"
#include "capsflow/core/bie/identity_term_cache.hpp"
#include "capsflow/core/bie/layer_options.hpp"
#include "capsflow/core/bie/near_field.hpp"
#include "capsflow/core/bie/quadrature.hpp"
#include "capsflow/core/phase_times.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {
namespace fmm {
struct Stresslet;
}  // namespace fmm

// The double layer's options: those both layers share (layer_options.hpp) and the reuse of D̃[1].
struct DoubleLayerOptions : LayerOptions {
  // Reuse D̃[1]'s quadrature error between refreshes on flat facets with the FMM back end
  // (identity_term_cache.hpp, docs/boundary-integral.md §4.7.5); false: a full pass on every set-up.
  bool reuse_identity_term = true;
};

// The automatic corrected layers (docs/boundary-integral.md §4.7.3): a band would buy about 1 % of
// the double layer's discretisation error for two thirds of its near-field work
// (perf/bie/double_layer_band), so none beyond the near ring.
inline constexpr int kAutoDoubleLayerCorrectedLayers = 1;

// Per inexact FMM (DoubleLayer::apply), loosest first: the allowance from which it is taken, its
// order, its applications.
struct InexactFmmUse {
  double allowed_error;
  int order;
  long applications;
};

// What the double layer reports about itself — summary.json's viscosity_ratio, capsflow info,
// perf/bie and the tests read it; the solve does not.
struct DoubleLayerDiagnostics {
  FarFieldBackend backend = FarFieldBackend::Direct;
  std::string backend_reason;
  Eigen::Index far_field_sources = 0;
  int fmm_order = 0;                  // 0 with the direct far field
  int refresh_fmm_order = 0;          // D̃[1]'s refresh pass's FMM order (fmm_order if not above it)
  int inexact_fmm_order = 0;          // the order taken from allowed_error = 1e-4; 0 without one
  std::vector<InexactFmmUse> inexact_fmm_uses;
  double blocks_per_node = 0;         // near-field blocks per node (6 doubles and an int each)
  double near_field_megabytes = 0;    // the near-field matrix: blocks, their columns, slots, row starts
  // Calls and their seconds: set_surface() (surface, near blocks, D̃[1], and its first application
  // if asked) and apply(); applications that took the cheaper inexact far field (single-precision
  // pairs or a lower-order FMM).
  long setups = 0, applications = 0, inexact_applications = 0;
  double setup_seconds = 0, apply_seconds = 0;
  bool reuses_identity_term = false;  // D̃[1]'s error term reused (flat facets, FMM back end)
  IdentityTermStats identity;         // its statistics (identity_term_cache.hpp)
};

class DoubleLayer {
 public:
  DoubleLayer(const Triangles& triangles, Eigen::Index n_nodes, const DoubleLayerOptions& opt = {});
  ~DoubleLayer();
  DoubleLayer(DoubleLayer&&) noexcept;

  // Everything that depends on the surface x only; call whenever the nodes move. Given u, also
  // Du = D_h[u] on the new surface (as apply(u, Du)) from the same far-field pass: the first
  // application of an iterative solve for the price of the set-up's own pass plus a few percent.
  // on_trajectory = false (a probe or an output off the solution's path) takes the reused error
  // term of D̃[1] as it is (or, if the surface jumped from its reference, the full pass for itself
  // only) and neither stores nor measures anything, so that such set-ups do not move the run.
  void set_surface(const Points& x, const Points* u = nullptr, Points* Du = nullptr, bool on_trajectory = true);
  // out_i = D_h[u](x_i) on the surface of the last set_surface() (out is resized to N×3).
  // allowed_error: the error the caller accepts, relative to ‖u‖ (an inexact Krylov step): from
  // 1e-3 the direct far field sums its pairs in single precision (where the build has AVX-512),
  // from 1e-4 the FMM back end uses FMMs of lower orders, the lower the larger the allowance
  // (tiers from 1e-4, 1e-3, 5e-3 and 1e-2: within a quarter of it relative to ‖u‖ in L2 and all of
  // it in max, double_layer_fmm_tolerance, backend_choice.hpp). Returns the L2 error bound it
  // committed, relative to ‖u‖: a tier's quarter of its allowance; the exact FMM's margin ×
  // tolerance whatever the allowance; 0 for the direct sum in double.
  double apply(const Points& u, Points& out, double allowed_error = 0);

  FarFieldBackend backend() const { return far_.backend(); }
  int fmm_order() const { return far_.fmm_order(); }  // 0 with the direct far field
  // Direct checks of the far field (LayerOptions::verify_every): on every verify_every-th
  // set_surface() (the first one included) the far field of the unit constants, D̃[1] (the
  // symmetric 3×3 per node), and that of the first application when set_surface is given u — both
  // summed by the same FMM (set-up, operators, order) as every apply() on that surface — are summed
  // again directly in full double precision and compared (compare_far_field); the check is the
  // worse of the two. Counted per surface: the log's `evaluation` is the set_surface() call.
  const FarFieldCheckLog& far_field_checks() const { return far_.checks(); }
  // Seconds in BieSources, BieFar and BieNear over all calls (the run's phase times).
  const PhaseTimes& times() const { return times_; }
  // D̃[1](x_i) in force on the current surface (the far pass's, or C + the reused error term).
  Mat3 unit_constant_integral(Eigen::Index i) const;
  // What the operator reports about itself (DoubleLayerDiagnostics).
  DoubleLayerDiagnostics diagnostics() const;
  // The reuse's records (per node E1, C1, E0, E−1 in the local frames; empty without the reuse) and
  // how many refreshes they hold: all that a set-up carries to the next, which a checkpoint keeps
  // so that a restarted run continues bit for bit. set_identity_records puts them back; records of
  // another size (another back end or mesh) are refused: false, nothing changed.
  const std::vector<double>& identity_records() const;
  int identity_record_count() const { return identity_ ? identity_->record_count() : 0; }
  bool set_identity_records(const std::vector<double>& records, int count);

 private:
  // An FMM of lower order for inexact steps (backend Fmm), added to the far field on the first
  // step that takes it (short runs may never take p = 5 or 7).
  struct InexactFmm {
    double allowed_error;
    double fmm_tolerance;  // the FMM's requested tolerance
    int order;             // the order it selects (fmm::order_for_tolerance)
    int fmm = -1;          // its handle in far_
    long applications = 0;
  };
  void build_inexact_ladder();
  void build_near_pattern();
  void visit_breadth_first();
  void place_points(const Points& x);
  void assemble_near_field(const Points& x);
  void assemble_row(Eigen::Index i, const Points& x);
  void add_elements(Eigen::Index i, const Points& x, IndexRange list, const int* slots, const std::vector<double>* y,
                    const std::vector<double>* n, int points, const double (*bary)[4]);
  bool identity_refresh(const Points& x, bool on_trajectory, bool verify_now, bool& sample_called);
  void sample_identity_term();  // sample_exact_: D̃[1] at the cache's samples, by direct sums
  void set_up_far_field(bool refresh, bool verify_now, const Points* u, Points* Du);
  void set_up_far_field_fmm(bool verify_now, const Points* u, Points* Du);
  void set_up_far_field_direct(const Points* u, Points* Du);
  void check_set_up(bool refresh, const Points* u, const Points* Du);
  void complete_diagonal(bool refresh, bool on_trajectory, bool sample_called);
  void fill_far_densities(const Points& u);                // density_ from u
  double apply_far_field(Points& out, double allowed_error);  // out = the far field of density_; the committed error
  void add_near_field(const Points& u, Points& out) const;  // out += near blocks and diagonal times u

  Triangles tri_;
  Eigen::Index n_nodes_;
  DoubleLayerOptions opt_;
  int threads_;
  GaussLegendre rule_, rule_u_;
  NearFieldLists lists_;
  BoundarySurface surface_;
  // Sources: each slot's position and weighted normal ñ = w N (= w n J); per source the summed ñ.
  FarField<fmm::Stresslet> far_;
  std::vector<InexactFmm> inexact_fmms_;  // loosest allowance first
  int refresh_fmm_ = -1;                  // the refresh pass's FMM in far_, if above the main one's order
  std::vector<double> band_y_, band_n_;   // the 3-point rule of every element (band): positions, w N
  std::vector<double> ring_y_, ring_n_;   // the 7-point rule of every element (near ring), likewise
  std::vector<double> density_;           // (u(y), ñ) per source: the far field of apply()
  std::vector<double> unit_far_;          // far field of the unit constants (6 per node, symmetric)
  // Near-field correction: per node i, symmetric blocks B_ij (xx yy zz xy xz yz) for the vertices j
  // of its touching, ring and band elements (CSR), and the diagonal ½ I − D̃[1](x_i), both scaled by
  // 1/8π. slot_ maps (node, listed element) to the blocks of its 3 vertices, in list order.
  std::vector<int> block_start_, block_col_, slot_start_, slot_;
  std::vector<double> block_, diagonal_;
  std::vector<int> node_order_;  // breadth-first over the mesh: the near-field assembly's visiting order
  std::unique_ptr<IdentityTermCache> identity_;  // D̃[1]'s reuse (flat facets, FMM back end)
  std::vector<double> sample_x_, sample_far_;    // the samples' positions, their far field of the unit constants
  std::vector<Mat3> sample_exact_;               // D̃[1] there
  PhaseTimes times_;
  double setup_seconds_ = 0, apply_seconds_ = 0;
  long setups_ = 0, applications_ = 0, inexact_applications_ = 0;
};

}  // namespace capsflow
