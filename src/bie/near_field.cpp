#include "capsflow/core/bie/near_field.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace capsflow {

NearFieldLists::NearFieldLists(const Triangles& t, Eigen::Index n_nodes, int ring_layers, int corrected_layers)
    : ring_layers_(ring_layers), corrected_layers_(corrected_layers) {
  if (ring_layers < 0 || corrected_layers < ring_layers)
    throw std::invalid_argument("near-field lists: need 0 <= ring_layers <= corrected_layers");
  const Eigen::Index m = t.rows();
  const std::size_t nn = static_cast<std::size_t>(n_nodes);
  // Edges: slots sorted by their vertex pair; the two slots of an edge end up side by side.
  std::vector<std::pair<std::pair<int, int>, int>> key(static_cast<std::size_t>(3 * m));
  for (Eigen::Index e = 0; e < m; ++e)
    for (int k = 0; k < 3; ++k) {
      const int a = t(e, k), b = t(e, (k + 1) % 3);
      key[static_cast<std::size_t>(3 * e + k)] = {{std::min(a, b), std::max(a, b)}, static_cast<int>(3 * e + k)};
    }
  std::sort(key.begin(), key.end());
  edge_of_.assign(key.size(), -1);
  for (std::size_t s = 0; s < key.size();) {
    std::size_t r = s + 1;
    while (r < key.size() && key[r].first == key[s].first) ++r;
    if (r - s > 2) throw std::invalid_argument("near-field lists: an edge is shared by more than two elements");
    const int id = static_cast<int>(sides_.size());
    sides_.push_back({key[s].second, r - s == 2 ? key[s + 1].second : -1});  // -1: a boundary edge
    for (std::size_t j = s; j < r; ++j) edge_of_[static_cast<std::size_t>(key[j].second)] = id;
    s = r;
  }
  // Node → touching elements.
  std::vector<int> ne_start(nn + 1, 0), ne;
  for (Eigen::Index e = 0; e < m; ++e)
    for (int k = 0; k < 3; ++k) ++ne_start[static_cast<std::size_t>(t(e, k)) + 1];
  for (std::size_t i = 0; i < nn; ++i) ne_start[i + 1] += ne_start[i];
  ne.resize(static_cast<std::size_t>(ne_start.back()));
  std::vector<int> fill(ne_start.begin(), ne_start.end() - 1);
  for (Eigen::Index e = 0; e < m; ++e)
    for (int k = 0; k < 3; ++k) ne[static_cast<std::size_t>(fill[static_cast<std::size_t>(t(e, k))]++)] = static_cast<int>(e);
  touch_start_ = ne_start;
  touch_ = ne;
  // Per node, a breadth-first search over vertices up to corrected_layers hops; an element's layer
  // is the smallest hop of its vertices. Stamps avoid clearing per node.
  std::vector<int> stamp_v(nn, -1), stamp_e(static_cast<std::size_t>(m), -1);
  std::vector<int> frontier, next, ring, band;
  ring_start_.assign(1, 0);
  band_start_.assign(1, 0);
  for (std::size_t i = 0; i < nn; ++i) {
    const int id = static_cast<int>(i);
    frontier.assign(1, id);
    stamp_v[i] = id;
    ring.clear(), band.clear();
    for (int layer = 0; layer <= corrected_layers; ++layer) {
      next.clear();
      for (int v : frontier)
        for (int s = ne_start[static_cast<std::size_t>(v)]; s < ne_start[static_cast<std::size_t>(v) + 1]; ++s) {
          const int e = ne[static_cast<std::size_t>(s)];
          if (stamp_e[static_cast<std::size_t>(e)] != id) {  // first reached from a vertex of this layer
            stamp_e[static_cast<std::size_t>(e)] = id;
            if (layer > 0) (layer <= ring_layers ? ring : band).push_back(e);
          }
          for (int k = 0; k < 3; ++k) {
            const int w = t(e, k);
            if (stamp_v[static_cast<std::size_t>(w)] != id) {
              stamp_v[static_cast<std::size_t>(w)] = id;
              next.push_back(w);
            }
          }
        }
      frontier.swap(next);
    }
    std::sort(ring.begin(), ring.end());
    std::sort(band.begin(), band.end());
    ring_.insert(ring_.end(), ring.begin(), ring.end());
    band_.insert(band_.end(), band.begin(), band.end());
    ring_start_.push_back(static_cast<int>(ring_.size()));
    band_start_.push_back(static_cast<int>(band_.size()));
  }
}

std::vector<std::array<int, 2>> far_field_source_slots(const NearFieldLists& lists, Eigen::Index n_elements,
                                                       bool edge_midpoints) {
  std::vector<std::array<int, 2>> slots;
  if (edge_midpoints) {
    slots.resize(static_cast<std::size_t>(lists.num_edges()));
    for (Eigen::Index edge = 0; edge < lists.num_edges(); ++edge) slots[static_cast<std::size_t>(edge)] = lists.sides(edge);
  } else {
    slots.resize(static_cast<std::size_t>(3 * n_elements));
    for (std::size_t slot = 0; slot < slots.size(); ++slot) slots[slot] = {static_cast<int>(slot), -1};
  }
  return slots;
}

}  // namespace capsflow
