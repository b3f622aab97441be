#pragma once
// Mesh quality statistics for reports: edge lengths, angles, valences.
#include <map>

#include "capsflow/core/types.hpp"

namespace capsflow {

struct MeshStats {
  long nodes = 0, elements = 0, edges = 0;
  double edge_min = 0, edge_mean = 0, edge_max = 0;
  double min_angle_deg = 0, max_angle_deg = 0;
  double area_min = 0, area_max = 0;
  std::map<int, long> valence_histogram;  // valence -> number of nodes
};

MeshStats mesh_stats(const SurfaceMesh& mesh);

// Shortest edge of the current mesh (for time-step estimates).
double min_edge_length(const SurfaceMesh& mesh);

}  // namespace capsflow
