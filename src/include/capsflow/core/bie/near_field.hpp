#pragma once
// Which elements each node integrates itself, and the far-field sources it takes back for them
// (docs/boundary-integral.md §4.2–4.3). Built once from the connectivity; it knows no kernel,
// so every layer operator over the same far-field sources can use it.
//
// The far field sums the edge-midpoint rule of every element: one point source per edge, at the
// edge's midpoint, carrying both adjacent elements' shares (their loads agree there). Seen from
// node i, each element falls in one class by its layer, the edge hops from i to its nearest vertex:
//   touching (layer 0)                — singular: the operator's exact element integral;
//   ring (layers 1 … ring_layers)     — near-singular: Dunavant's 7-point rule (or refined);
//   band (… up to corrected_layers)   — the 3-point Gauss rule;
// and node i subtracts the far field's midpoint shares of all these elements. Elements beyond
// stay with the midpoint rule.
#include <array>
#include <vector>

#include "capsflow/core/types.hpp"

namespace capsflow {

// A contiguous run of element (or slot) indices in one of the lists below.
struct IndexRange {
  const int* first;
  const int* last;
  const int* begin() const { return first; }
  const int* end() const { return last; }
  std::size_t size() const { return static_cast<std::size_t>(last - first); }
};

class NearFieldLists {
 public:
  // ring_layers ≥ 0 and corrected_layers ≥ ring_layers (edge hops beyond the touching elements).
  NearFieldLists(const Triangles& t, Eigen::Index n_nodes, int ring_layers, int corrected_layers);

  IndexRange touching(Eigen::Index i) const { return range(touch_start_, touch_, i); }
  IndexRange ring(Eigen::Index i) const { return range(ring_start_, ring_, i); }
  IndexRange band(Eigen::Index i) const { return range(band_start_, band_, i); }

  // Edges: edge(e, k) is the edge of element e from its vertex k to k + 1; a slot 3e + k is that
  // element's share of it, and sides(edge) the two slots of an edge (first: the lower element).
  Eigen::Index num_edges() const { return static_cast<Eigen::Index>(sides_.size()); }
  int edge(Eigen::Index e, int k) const { return edge_of_[static_cast<std::size_t>(3 * e + k)]; }
  const std::vector<int>& edge_of_slot() const { return edge_of_; }
  const std::array<int, 2>& sides(Eigen::Index edge) const { return sides_[static_cast<std::size_t>(edge)]; }
  int ring_layers() const { return ring_layers_; }
  int corrected_layers() const { return corrected_layers_; }

 private:
  static IndexRange range(const std::vector<int>& start, const std::vector<int>& list, Eigen::Index i) {
    const int* base = list.data();
    return {base + start[static_cast<std::size_t>(i)], base + start[static_cast<std::size_t>(i) + 1]};
  }
  int ring_layers_, corrected_layers_;
  std::vector<int> touch_start_, touch_, ring_start_, ring_, band_start_, band_;  // CSR per node
  std::vector<int> edge_of_;                                                   // per slot 3e + k
  std::vector<std::array<int, 2>> sides_;                                      // per edge
};

// The far field's point sources: element e's rule point k is slot 3e + k. With the edge-midpoint
// rule the two slots of an edge (its two sides) are one source; otherwise every slot is one.
// Per source its slots, the second −1 when alone (or on a boundary edge).
std::vector<std::array<int, 2>> far_field_source_slots(const NearFieldLists& lists, Eigen::Index n_elements,
                                                       bool edge_midpoints);

}  // namespace capsflow
