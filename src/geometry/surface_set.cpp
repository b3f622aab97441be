#include "capsflow/core/geometry/surface_set.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace capsflow {

SurfaceSet::SurfaceSet(const std::vector<SurfaceMesh>& parts) {
  if (parts.empty()) throw std::invalid_argument("surface set: no surface");
  Eigen::Index nodes = 0, elements = 0;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const SurfaceMesh& m = parts[k];
    if (m.num_nodes() == 0 || m.num_elements() == 0)
      throw std::invalid_argument(fmt::format("surface set: surface {} has no nodes or no elements", k));
    if (m.triangles.minCoeff() < 0 || m.triangles.maxCoeff() >= m.num_nodes())
      throw std::invalid_argument(
          fmt::format("surface set: surface {} has a triangle index outside its {} nodes", k, m.num_nodes()));
    parts_.push_back({nodes, m.num_nodes(), elements, m.num_elements()});
    nodes += m.num_nodes();
    elements += m.num_elements();
  }
  union_.vertices.resize(nodes, 3);
  union_.triangles.resize(elements, 3);
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const SurfacePart& p = parts_[k];
    union_.vertices.middleRows(p.node_begin, p.nodes) = parts[k].vertices;
    union_.triangles.middleRows(p.element_begin, p.elements) =
        parts[k].triangles.array() + static_cast<int>(p.node_begin);
  }
}

Triangles SurfaceSet::local_triangles(int k) const {
  const SurfacePart& p = part(k);
  return union_.triangles.middleRows(p.element_begin, p.elements).array() - static_cast<int>(p.node_begin);
}

SurfaceMesh SurfaceSet::part_mesh(const Points& x, int k) const {
  const SurfacePart& p = part(k);
  return {x.middleRows(p.node_begin, p.nodes), local_triangles(k)};
}

int SurfaceSet::part_of_node(Eigen::Index node) const {
  if (node < 0 || node >= union_.num_nodes()) throw std::out_of_range(fmt::format("surface set: no node {}", node));
  const auto it = std::upper_bound(parts_.begin(), parts_.end(), node,
                                   [](Eigen::Index i, const SurfacePart& p) { return i < p.node_begin; });
  return static_cast<int>(it - parts_.begin()) - 1;
}

int SurfaceSet::part_of_element(Eigen::Index element) const {
  if (element < 0 || element >= union_.num_elements())
    throw std::out_of_range(fmt::format("surface set: no element {}", element));
  const auto it = std::upper_bound(parts_.begin(), parts_.end(), element,
                                   [](Eigen::Index e, const SurfacePart& p) { return e < p.element_begin; });
  return static_cast<int>(it - parts_.begin()) - 1;
}

}  // namespace capsflow
