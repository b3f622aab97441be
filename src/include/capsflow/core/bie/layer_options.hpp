#pragma once
// The options both layer operators read (single_layer.hpp, double_layer.hpp): the far field's
// back end, tolerance and rule (far_field.hpp), the surface, and the near field's quadrature; and
// what their automatic values resolve to. Each operator's own options add to these:
// SingleLayerOptions (the refined ring) and DoubleLayerOptions (the reuse of D̃[1]).
#include "capsflow/core/bie/backend_choice.hpp"

namespace capsflow {

struct LayerOptions {
  BackendRequest backend = BackendRequest::Auto;
  double tolerance = 1e-6;       // far-field relative accuracy: the FMM order and the back-end crossover;
                                 // the single layer's direct sums use single-precision pairs (~5e-7) from
                                 // 1e-5 on, double below
  double fmm_tolerance = 0;      // > 0: the FMM back end's accuracy instead of `tolerance` (the crossover
                                 // and the direct sums keep `tolerance`); fluid.tolerance = "auto" sets it
  SurfaceGeometry geometry = SurfaceGeometry::Flat;  // flat facets or their quadratic lift
  FarFieldRule far_rule = FarFieldRule::Auto;  // Auto: edge midpoints on flat facets, Gauss points on curved
  int fmm_order = 0;             // > 0 forces the FMM order instead of the one the tolerance calls for
  int fmm_leaf_size = 0;         // > 0 forces the FMM's points per leaf instead of the calibrated one
  // > 0: every verify_every-th evaluation (the single layer's apply(), the double layer's
  // set_surface(); the first one included) the far field is summed again directly, in full double
  // precision, on the same sources and targets (far_field_checks()).
  int verify_every = 0;
  int threads = 0;               // 0 = OpenMP default (set per parallel region, never globally)

  // Not scene keys: the quadrature's parameters, at the values docs/boundary-integral.md §4.1–4.2
  // and §4.7.3 measured. perf/bie/bie_bench varies them for the single layer (cost against
  // accuracy), perf/bie/double_layer_band the ring and band for the double layer, and
  // tests/core/bie/test_single_layer.cpp reads the singular points and sets a wide band.
  // Touching elements: the flat facet is integrated in closed form; a curved element adds its
  // curvature correction by Duffy quadrature with these Gauss–Legendre points (quadrature.hpp).
  int singular_points = 4;          // in v, on each side of the foot v*
  int singular_radial_points = 3;   // in u (at most 16)
  int near_ring_layers = 0;      // edge hops of the ring beyond the touching elements; 0 = auto: 1 for
                                 // flat (the O(h²) geometry error dominates), 2 for curved (the far
                                 // field's O(h) quadrature error would otherwise dominate)
  int corrected_layers = 0;      // edge hops within which the far field's midpoint rule is replaced
                                 // (beyond the ring: by the 3-point rule); 0 = auto (the operator's own);
                                 // with the Gauss-point far field there is no band (the ring's layers)
};

// The OpenMP threads of every parallel region of an operator: `threads`, or the OpenMP default.
int layer_threads(const LayerOptions& o);
// What the FMM back end promises relative to max |v|: fmm_tolerance where given, else tolerance.
double fmm_promise(const LayerOptions& o);
// The single layer's FMM order: the forced one, or the one the Stokeslet calibration gives for
// kFmmToleranceMargin × fmm_promise (what FarField asks its main FMM for).
int single_layer_fmm_order(const LayerOptions& o);
// The far-field rule the options resolve to.
FarFieldRule far_field_rule(const LayerOptions& o);
// The far field's sources for a surface of `elements` elements and `edges` edges under that rule:
// one per edge (midpoints) or three per element (Gauss points). What SingleLayer and DoubleLayer
// count, for callers that size a run without building them.
Eigen::Index far_field_source_count(const LayerOptions& o, Eigen::Index elements, Eigen::Index edges);
// The near ring's edge hops (the automatic value where near_ring_layers is 0).
int near_ring_layers(const LayerOptions& o);
// The corrected layers: `automatic` where corrected_layers is 0, never fewer than `ring_layers`
// (the ring's), and no band beyond the ring with the Gauss-point far field (a band would integrate
// with the far field's own rule).
int corrected_layers(const LayerOptions& o, int ring_layers, int automatic);

}  // namespace capsflow
