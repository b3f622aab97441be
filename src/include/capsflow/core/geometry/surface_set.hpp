#pragma once
// Several closed surfaces as one mesh: their nodes and triangles concatenated in order (the
// disjoint union), with the range each part occupies. The boundary integrals run on the union —
// one far field over every surface, each surface's own singular quadrature, since no element of
// one part shares a node with another — and what belongs to one surface is found by its range.
#include <vector>

#include "capsflow/core/types.hpp"

namespace capsflow {

struct SurfacePart {
  Eigen::Index node_begin = 0, nodes = 0;        // rows [node_begin, node_begin + nodes) of the union
  Eigen::Index element_begin = 0, elements = 0;  // triangles [element_begin, element_begin + elements)
};

class SurfaceSet {
 public:
  // Throws std::invalid_argument naming the part for an empty list, a part without nodes or
  // elements, or a triangle index outside its part.
  explicit SurfaceSet(const std::vector<SurfaceMesh>& parts);

  int size() const { return static_cast<int>(parts_.size()); }
  const SurfacePart& part(int k) const { return parts_.at(static_cast<std::size_t>(k)); }
  const SurfaceMesh& mesh() const { return union_; }  // the parts' positions as given
  // Surface k on its own: its triangles in its own node numbering, and its mesh at positions x
  // (the union's rows).
  Triangles local_triangles(int k) const;
  SurfaceMesh part_mesh(const Points& x, int k) const;
  int part_of_node(Eigen::Index node) const;
  int part_of_element(Eigen::Index element) const;

 private:
  std::vector<SurfacePart> parts_;
  SurfaceMesh union_;
};

}  // namespace capsflow
