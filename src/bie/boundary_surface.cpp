#include "capsflow/core/bie/boundary_surface.hpp"

namespace capsflow {

BoundarySurface::BoundarySurface(const Triangles& triangles, SurfaceGeometry geometry)
    : tri_(triangles), curved_(geometry == SurfaceGeometry::Curved) {
  if (curved_) mid_.resize(static_cast<size_t>(3 * tri_.rows()));
}

void BoundarySurface::update(const Points& x, int threads) {
  if (!curved_) return;  // flat facets need no midpoints (element() builds them)
  vertex_normals_max(x, tri_, normals_);
  const Eigen::Index m = tri_.rows();
#pragma omp parallel for schedule(static) num_threads(threads)
  for (Eigen::Index e = 0; e < m; ++e)
    for (int k = 0; k < 3; ++k) {
      const int a = tri_(e, k), b = tri_(e, (k + 1) % 3);
      mid_[static_cast<size_t>(3 * e + k)] = hermite_edge_midpoint(x.row(a).transpose(), x.row(b).transpose(),
                                                                   normals_.row(a).transpose(), normals_.row(b).transpose());
    }
}

QuadraticTriangle BoundarySurface::element(const Points& x, Eigen::Index e, int first) const {
  const int k1 = (first + 1) % 3, k2 = (first + 2) % 3;
  if (!curved_)
    return QuadraticTriangle::flat(x.row(tri_(e, first)).transpose(), x.row(tri_(e, k1)).transpose(),
                                   x.row(tri_(e, k2)).transpose());
  const Vec3* m = &mid_[static_cast<size_t>(3 * e)];
  return QuadraticTriangle(x.row(tri_(e, first)).transpose(), x.row(tri_(e, k1)).transpose(), x.row(tri_(e, k2)).transpose(),
                           m[first], m[k1], m[k2]);
}

}  // namespace capsflow
