#pragma once
// The single layer over several surfaces (docs/boundary-integral.md §4.9): at every node of every
// surface, u_i = (1/8π) Σ_k ∫_{S_k} G(x_i − y)·q(y) dS_y. One SingleLayer on the disjoint union
// sums the far field of all surfaces in one pass (FMM or direct, chosen from the total counts)
// and corrects each surface's own near field; CrossNearField corrects the elements of the other
// surfaces within kCrossNearRatio sizes of a node. With one surface it is that surface's
// SingleLayer, and nothing more runs.
#include "capsflow/core/bie/cross_near_field.hpp"
#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/geometry/surface_set.hpp"

namespace capsflow {

class MultiSurfaceSingleLayer {
 public:
  explicit MultiSurfaceSingleLayer(const SurfaceSet& set, const SingleLayerOptions& opt = {},
                                   double near_ratio = kCrossNearRatio);

  // u at every row of x (the union's positions; q its load), resized to the union's nodes. With
  // `pairs_found`, the cross pairs of find_pairs(x), called before on the same x, are used.
  void apply(const Points& x, const Points& q, Points& u, bool pairs_found = false);
  // The cross-surface search alone (cross()), e.g. for contact forces before the loads are known.
  void find_pairs(const Points& x) { cross_.find_pairs(x); }

  const SingleLayer& layer() const { return layer_; }
  const CrossNearField& cross() const { return cross_; }
  const SurfaceGap& closest() const { return cross_.closest(); }
  int surfaces() const { return surfaces_; }

 private:
  int surfaces_;
  SingleLayer layer_;
  CrossNearField cross_;
};

}  // namespace capsflow
