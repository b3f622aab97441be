#include "capsflow/core/mesh/stats.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/mesh/topology.hpp"

namespace capsflow {

MeshStats mesh_stats(const SurfaceMesh& mesh) {
  MeshStats s;
  s.nodes = mesh.num_nodes();
  s.elements = mesh.num_elements();
  const auto edges = mesh_edges(mesh);
  s.edges = edges.rows();
  double sum = 0;
  s.edge_min = std::numeric_limits<double>::infinity();
  for (Eigen::Index k = 0; k < edges.rows(); ++k) {
    const double l = (mesh.vertices.row(edges(k, 0)) - mesh.vertices.row(edges(k, 1))).norm();
    s.edge_min = std::min(s.edge_min, l);
    s.edge_max = std::max(s.edge_max, l);
    sum += l;
  }
  s.edge_mean = edges.rows() ? sum / static_cast<double>(edges.rows()) : 0;
  s.min_angle_deg = 180;
  for (Eigen::Index e = 0; e < mesh.num_elements(); ++e)
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = mesh.vertices.row(mesh.triangles(e, k)).transpose();
      const Vec3 a = mesh.vertices.row(mesh.triangles(e, (k + 1) % 3)).transpose() - p;
      const Vec3 b = mesh.vertices.row(mesh.triangles(e, (k + 2) % 3)).transpose() - p;
      const double ang = std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
      s.min_angle_deg = std::min(s.min_angle_deg, ang);
      s.max_angle_deg = std::max(s.max_angle_deg, ang);
    }
  const Eigen::VectorXd area = element_areas(mesh);
  s.area_min = area.size() ? area.minCoeff() : 0;
  s.area_max = area.size() ? area.maxCoeff() : 0;
  std::vector<int> valence(static_cast<size_t>(mesh.num_nodes()), 0);
  for (Eigen::Index e = 0; e < mesh.num_elements(); ++e)
    for (int k = 0; k < 3; ++k) ++valence[mesh.triangles(e, k)];
  for (int v : valence) ++s.valence_histogram[v];
  return s;
}

double min_edge_length(const SurfaceMesh& mesh) {
  double m = std::numeric_limits<double>::infinity();
  for (Eigen::Index e = 0; e < mesh.num_elements(); ++e)
    for (int k = 0; k < 3; ++k)
      m = std::min(m, (mesh.vertices.row(mesh.triangles(e, k)) - mesh.vertices.row(mesh.triangles(e, (k + 1) % 3))).norm());
  return m;
}

}  // namespace capsflow
