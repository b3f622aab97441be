#pragma once
// Topological validation of a user mesh: a capsule wall must be a closed, edge-manifold,
// vertex-manifold, consistently oriented triangulation of a sphere (one component, Euler
// characteristic 2), without degenerate elements or unused vertices. Errors name the problem
// and the first offending element or vertex (0-based indices).
#include <stdexcept>
#include <string>

#include "capsflow/core/types.hpp"

namespace capsflow {

class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws MeshError describing the first problem found. If the mesh is consistently oriented but
// inward (negative enclosed volume), flips all triangles and returns true; otherwise false.
bool validate_closed_surface(SurfaceMesh& mesh);

// Unique undirected edges (i < j), in first-seen order.
Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor> mesh_edges(const SurfaceMesh& mesh);

}  // namespace capsflow
