#include "capsflow/core/scene/boundary_integral_options.hpp"

#include <algorithm>

#include <fmt/core.h>

namespace capsflow {

namespace {
// fluid.tolerance = "auto", measured on the four paper cases against a 1e-8 far field, D_ij at every
// output to γ̇t = 5 (perf/bie/far_tolerance.md; docs/boundary-integral.md §4.3.2):
// - the direct sums and the crossover at 1e-6: a looser tolerance only moves the direct sum to
//   single-precision pairs, ≤ 14 % cheaper per evaluation but up to 9 % more evaluations (1 280 and
//   5 120 elements), so it does not pay;
constexpr double kAutoDirectTolerance = 1e-6;
// - the single layer's FMM at 1e-5 (order 8 instead of 9): 24 % less wall time at 20 480 elements,
//   D_ij within 3.3e-6 (Fig. 4) and 2.1e-5 (Table 1, α = 3 %) of the reference, a fifth of the
//   1e-4 that the time tolerance keeps; 1e-4 already moves Table 1's D_ij by 2.9e-4.
constexpr double kAutoFmmTolerance = 1e-5;
// The smallest tolerance a scene accepts (the direct sums are accurate to ~1e-9).
constexpr double kSmallestTolerance = 1e-8;

// What both layers read of fluid.*, with fluid.tolerance resolved (t).
void set_layer_options(const Scene& s, const FarFieldTolerance& t, int threads, LayerOptions& o) {
  o.backend = s.fluid.backend;
  o.tolerance = t.tolerance;
  o.geometry = s.fluid.geometry;
  o.far_rule = s.fluid.far_rule;
  o.fmm_order = s.fluid.fmm_order;
  o.fmm_leaf_size = s.fluid.fmm_leaf_size;
  o.verify_every = s.fluid.verify_every;
  o.threads = threads;
}
}  // namespace

FarFieldTolerance far_field_tolerance(const Scene& s) {
  FarFieldTolerance t;
  if (!s.fluid.tolerance_auto) {
    t.tolerance = t.fmm_tolerance = s.fluid.tolerance;
    t.reason = "given";
    return t;
  }
  t.tolerance = t.fmm_tolerance = kAutoDirectTolerance;
  const bool error_control = is_stabilized(s.time.scheme) && s.time.dt_auto;
  if (s.fluid.viscosity_ratio != 1.0) {
    t.reason = fmt::format("auto: {:g}; λ ≠ 1 (the second-kind solve's tolerance too)", t.tolerance);
  } else if (!error_control) {
    t.reason = fmt::format("auto: {:g}; no error control sets the step's accuracy", t.tolerance);
  } else if (!s.time.tolerance_auto && s.time.tolerance < kAutoFmmTolerance) {
    t.fmm_tolerance = std::max(kSmallestTolerance, s.time.tolerance);
    t.reason = fmt::format("auto: {:g} for direct sums, {:g} for the FMM (never looser than time.tolerance = {:g})",
                           t.tolerance, t.fmm_tolerance, s.time.tolerance);
  } else {
    t.fmm_tolerance = kAutoFmmTolerance;
    t.reason = fmt::format("auto: {:g} for direct sums, {:g} for the FMM", t.tolerance, t.fmm_tolerance);
  }
  return t;
}

SingleLayerOptions boundary_integral_options(const Scene& s, int threads) {
  const FarFieldTolerance t = far_field_tolerance(s);
  SingleLayerOptions o;
  set_layer_options(s, t, threads, o);
  o.fmm_tolerance = t.fmm_tolerance;  // the single layer's FMM only: the rule loosens nothing else
  return o;
}

DoubleLayerOptions double_layer_options(const Scene& s, int threads) {
  DoubleLayerOptions o;
  set_layer_options(s, far_field_tolerance(s), threads, o);
  o.reuse_identity_term = s.fluid.reuse_identity_term;
  return o;
}

}  // namespace capsflow
