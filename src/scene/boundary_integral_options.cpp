#include "capsflow/core/scene/boundary_integral_options.hpp"

namespace capsflow {

SingleLayerOptions boundary_integral_options(const Scene& s, int threads) {
  SingleLayerOptions o;
  o.backend = s.fluid.backend;
  o.tolerance = s.fluid.tolerance;
  o.geometry = s.fluid.geometry;
  o.far_rule = s.fluid.far_rule;
  o.fmm_order = s.fluid.fmm_order;
  o.fmm_leaf_size = s.fluid.fmm_leaf_size;
  o.verify_every = s.fluid.verify_every;
  o.reuse_identity_term = s.fluid.reuse_identity_term;
  o.threads = threads;
  return o;
}

}  // namespace capsflow
