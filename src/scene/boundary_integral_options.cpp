#include "capsflow/core/scene/boundary_integral_options.hpp"

namespace capsflow {

namespace {
// What both layers read of fluid.*.
void set_layer_options(const Scene& s, int threads, LayerOptions& o) {
  o.backend = s.fluid.backend;
  o.tolerance = s.fluid.tolerance;
  o.geometry = s.fluid.geometry;
  o.far_rule = s.fluid.far_rule;
  o.fmm_order = s.fluid.fmm_order;
  o.fmm_leaf_size = s.fluid.fmm_leaf_size;
  o.verify_every = s.fluid.verify_every;
  o.threads = threads;
}
}  // namespace

SingleLayerOptions boundary_integral_options(const Scene& s, int threads) {
  SingleLayerOptions o;
  set_layer_options(s, threads, o);
  return o;
}

DoubleLayerOptions double_layer_options(const Scene& s, int threads) {
  DoubleLayerOptions o;
  set_layer_options(s, threads, o);
  o.reuse_identity_term = s.fluid.reuse_identity_term;
  return o;
}

}  // namespace capsflow
