#pragma once
// Mesh connectivity built once per mesh: node -> element incidence, node adjacency (the sparsity
// pattern of nodal matrices), and a greedy element colouring (no two elements of one colour share
// a node). The membrane pass runs colour by colour, elements of a colour in parallel, each element
// adding directly into nodal arrays; the GSMB pass stores each element's contributions and sums
// them node by node in colour order. Either way the summation order at every node is fixed by the
// colouring, so results are bit-identical for any thread count.
#include <array>
#include <vector>

#include "capsflow/shell/types.hpp"

namespace capsflow::shell {

struct Topology {
  Topology() = default;
  Topology(const Triangles& tri, Eigen::Index n_nodes);

  int n_nodes = 0, n_elems = 0;
  std::vector<std::array<int, 3>> tri;           ///< element nodes
  std::vector<int> inc_ptr, inc_elem, inc_local;  ///< incident elements of node i: [inc_ptr[i], inc_ptr[i+1])
  std::vector<int> adj_ptr, adj;                  ///< sorted neighbours of node i (including i)
  std::vector<std::vector<int>> colors;           ///< element colouring
  /// for element e and local pair (a, b): position of node b in the adjacency row of node a,
  /// relative to adj_ptr[node a]; index a*3+b.
  std::vector<std::array<int, 9>> pair_pos;
  std::vector<int> diag_pos;  ///< position of i in its own adjacency row (relative)
  /// the incidence of node i ordered by the colour of the element, [inc_ptr[i], inc_ptr[i+1]):
  /// the order in which a colour-by-colour pass adds the elements' contributions to node i
  std::vector<int> inc_elem_by_colour, inc_local_by_colour;
  int nnz_nodes() const { return static_cast<int>(adj.size()); }
};

}  // namespace capsflow::shell
