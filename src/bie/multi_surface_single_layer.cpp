#include "capsflow/core/bie/multi_surface_single_layer.hpp"

namespace capsflow {

MultiSurfaceSingleLayer::MultiSurfaceSingleLayer(const SurfaceSet& set, const SingleLayerOptions& opt, double near_ratio)
    : surfaces_(set.size()),
      layer_(set.mesh().triangles, set.mesh().num_nodes(), opt),
      cross_(set, near_ratio, layer_threads(opt)) {}

void MultiSurfaceSingleLayer::apply(const Points& x, const Points& q, Points& u, bool pairs_found) {
  layer_.apply(x, q, u);
  if (surfaces_ == 1) return;
  if (!pairs_found) cross_.find_pairs(x);
  cross_.correct(x, q, layer_, u);
}

}  // namespace capsflow
