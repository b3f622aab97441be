#include "capsflow/core/stepping/grid_scale_filter.hpp"

#include <stdexcept>

namespace capsflow {

GridScaleFilter::GridScaleFilter(const Triangles& triangles, int passes)
    : umbrella_(triangles, triangles.size() > 0 ? triangles.maxCoeff() + 1 : 0), passes_(passes) {
  if (passes < 0) throw std::invalid_argument("GridScaleFilter: the number of passes must not be negative");
}

void GridScaleFilter::apply(Points& v) {
  for (int p = 0; p < passes_; ++p) {
    umbrella_.apply(v, u_);
    v.noalias() += 0.5 * u_;
  }
}

}  // namespace capsflow
