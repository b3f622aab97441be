#include "capsflow/core/bie/layer_options.hpp"

#include <omp.h>

#include <algorithm>

#include "capsflow/fmm/calibration.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow {

double fmm_promise(const LayerOptions& o) { return o.fmm_tolerance > 0 ? o.fmm_tolerance : o.tolerance; }

int single_layer_fmm_order(const LayerOptions& o) {
  return o.fmm_order > 0 ? o.fmm_order : fmm::order_for_tolerance<fmm::Stokeslet>(kFmmToleranceMargin * fmm_promise(o));
}

int layer_threads(const LayerOptions& o) { return o.threads > 0 ? o.threads : omp_get_max_threads(); }

FarFieldRule far_field_rule(const LayerOptions& o) {
  if (o.far_rule != FarFieldRule::Auto) return o.far_rule;
  return o.geometry == SurfaceGeometry::Curved ? FarFieldRule::GaussPoints : FarFieldRule::EdgeMidpoints;
}

Eigen::Index far_field_source_count(const LayerOptions& o, Eigen::Index elements, Eigen::Index edges) {
  return far_field_rule(o) == FarFieldRule::EdgeMidpoints ? edges : 3 * elements;
}

int near_ring_layers(const LayerOptions& o) {
  return o.near_ring_layers > 0 ? o.near_ring_layers : (o.geometry == SurfaceGeometry::Curved ? 2 : 1);
}

int corrected_layers(const LayerOptions& o, int ring_layers, int automatic) {
  if (far_field_rule(o) == FarFieldRule::GaussPoints) return ring_layers;
  return std::max(ring_layers, o.corrected_layers > 0 ? o.corrected_layers : automatic);
}

}  // namespace capsflow
