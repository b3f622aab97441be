#pragma once
// The surface the boundary integrals see at the current positions (docs/boundary-integral.md §4.5):
// the flat P1 facets, or (geometry "curved") their quadratic lift through the vertex normals and
// the Hermite edge midpoints of curved_triangle.hpp. update() once per surface, then element()
// writes any element about any of its vertices.
#include <vector>

#include "capsflow/core/bie/backend_choice.hpp"
#include "capsflow/core/bie/curved_triangle.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

class BoundarySurface {
 public:
  BoundarySurface(const Triangles& triangles, SurfaceGeometry geometry);

  bool curved() const { return curved_; }
  const Triangles& triangles() const { return tri_; }
  // Vertex normals and lifted edge midpoints of the surface x (nothing to do for flat facets).
  void update(const Points& x, int threads);
  // Element e written about its vertex `first` (0, 1, 2), vertices in the element's cyclic order.
  QuadraticTriangle element(const Points& x, Eigen::Index e, int first) const;

 private:
  Triangles tri_;
  bool curved_;
  Points normals_;        // vertex normals (curved only)
  std::vector<Vec3> mid_;  // edge midpoints: mid_[3e + k] on edge (k, k+1)
};

}  // namespace capsflow
