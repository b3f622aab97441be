// The near-field lists (bie/near_field.hpp) against an independent construction: hop distances
// from a dense all-pairs breadth-first search over the vertex adjacency, and edges from the
// mesh's own edge list (mesh/topology.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <queue>
#include <set>

#include "capsflow/core/bie/near_field.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/mesh/topology.hpp"

using namespace capsflow;

namespace {

// hops[i][v]: edge hops from vertex i to vertex v.
std::vector<std::vector<int>> all_hops(const SurfaceMesh& m) {
  const Eigen::Index n = m.num_nodes();
  std::vector<std::set<int>> adj(static_cast<size_t>(n));
  for (Eigen::Index e = 0; e < m.num_elements(); ++e)
    for (int k = 0; k < 3; ++k) {
      adj[static_cast<size_t>(m.triangles(e, k))].insert(m.triangles(e, (k + 1) % 3));
      adj[static_cast<size_t>(m.triangles(e, (k + 1) % 3))].insert(m.triangles(e, k));
    }
  std::vector<std::vector<int>> hops(static_cast<size_t>(n), std::vector<int>(static_cast<size_t>(n), -1));
  for (Eigen::Index i = 0; i < n; ++i) {
    auto& h = hops[static_cast<size_t>(i)];
    std::queue<int> q;
    h[static_cast<size_t>(i)] = 0;
    q.push(static_cast<int>(i));
    while (!q.empty()) {
      const int v = q.front();
      q.pop();
      for (int w : adj[static_cast<size_t>(v)])
        if (h[static_cast<size_t>(w)] < 0) h[static_cast<size_t>(w)] = h[static_cast<size_t>(v)] + 1, q.push(w);
    }
  }
  return hops;
}

}  // namespace

TEST(NearFieldLists, EveryElementIsInTheClassOfItsLayer) {
  // An octahedron sphere (valence 4 and 6 vertices) and an icosphere (valence 5 and 6).
  for (const auto base : {BaseSolid::Octahedron, BaseSolid::Icosahedron}) {
    const SurfaceMesh m = make_sphere_mesh(base, 2);
    const auto hops = all_hops(m);
    for (const auto& [ring_layers, corrected] : {std::pair{1, 3}, {2, 4}, {0, 2}, {1, 1}}) {
      const NearFieldLists L(m.triangles, m.num_nodes(), ring_layers, corrected);
      for (Eigen::Index i = 0; i < m.num_nodes(); ++i) {
        std::vector<int> touching, ring, band;
        for (Eigen::Index e = 0; e < m.num_elements(); ++e) {
          int layer = 1 << 30;
          for (int k = 0; k < 3; ++k) layer = std::min(layer, hops[static_cast<size_t>(i)][static_cast<size_t>(m.triangles(e, k))]);
          if (layer == 0) touching.push_back(static_cast<int>(e));
          else if (layer <= ring_layers) ring.push_back(static_cast<int>(e));
          else if (layer <= corrected) band.push_back(static_cast<int>(e));
        }
        auto sorted = [](IndexRange r) {
          std::vector<int> v(r.begin(), r.end());
          std::sort(v.begin(), v.end());
          return v;
        };
        ASSERT_EQ(sorted(L.touching(i)), touching) << "node " << i;
        ASSERT_EQ(sorted(L.ring(i)), ring) << "node " << i << " ring " << ring_layers;
        ASSERT_EQ(sorted(L.band(i)), band) << "node " << i << " layers " << ring_layers << ".." << corrected;
      }
    }
  }
}

TEST(NearFieldLists, EachEdgeHasTwoSidesWithTheSameEnds) {
  const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 2);
  const NearFieldLists L(m.triangles, m.num_nodes(), 1, 2);
  EXPECT_EQ(L.num_edges(), mesh_edges(m).rows());  // one far-field source per edge of the mesh
  std::vector<int> seen(static_cast<size_t>(3 * m.num_elements()), 0);
  for (Eigen::Index edge = 0; edge < L.num_edges(); ++edge) {
    const auto& s = L.sides(edge);
    ASSERT_GE(s[0], 0);
    ASSERT_GE(s[1], 0);  // a closed surface has no boundary edge
    auto ends = [&](int slot) {
      const int e = slot / 3, k = slot % 3;
      const int a = m.triangles(e, k), b = m.triangles(e, (k + 1) % 3);
      return std::pair{std::min(a, b), std::max(a, b)};
    };
    EXPECT_EQ(ends(s[0]), ends(s[1]));
    EXPECT_NE(s[0] / 3, s[1] / 3);  // two different elements
    for (int slot : s) {
      EXPECT_EQ(L.edge(slot / 3, slot % 3), edge);
      ++seen[static_cast<size_t>(slot)];
    }
  }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; }));  // every slot on exactly one edge
}

TEST(NearFieldLists, RejectsALayerOrderThatCannotHold) {
  const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 1);
  EXPECT_THROW(NearFieldLists(m.triangles, m.num_nodes(), 2, 1), std::invalid_argument);
  EXPECT_THROW(NearFieldLists(m.triangles, m.num_nodes(), -1, 1), std::invalid_argument);
}
