#include "capsflow/shell/topology.hpp"

#include <algorithm>
#include <stdexcept>

namespace capsflow::shell {

Topology::Topology(const Triangles& T, Eigen::Index nn) {
  n_nodes = static_cast<int>(nn);
  n_elems = static_cast<int>(T.rows());
  tri.resize(n_elems);
  std::vector<int> count(n_nodes + 1, 0);
  for (int e = 0; e < n_elems; ++e)
    for (int k = 0; k < 3; ++k) {
      const int v = T(e, k);
      if (v < 0 || v >= n_nodes) throw std::invalid_argument("shell::Topology: node index out of range");
      tri[e][k] = v;
      ++count[v + 1];
    }
  inc_ptr.assign(n_nodes + 1, 0);
  for (int i = 0; i < n_nodes; ++i) inc_ptr[i + 1] = inc_ptr[i] + count[i + 1];
  inc_elem.resize(inc_ptr.back());
  inc_local.resize(inc_ptr.back());
  std::vector<int> fill(inc_ptr.begin(), inc_ptr.end() - 1);
  for (int e = 0; e < n_elems; ++e)
    for (int k = 0; k < 3; ++k) {
      const int v = tri[e][k];
      inc_elem[fill[v]] = e;
      inc_local[fill[v]] = k;
      ++fill[v];
    }
  // adjacency
  adj_ptr.assign(n_nodes + 1, 0);
  std::vector<std::vector<int>> rows(n_nodes);
  for (int i = 0; i < n_nodes; ++i) {
    auto& r = rows[i];
    r.push_back(i);
    for (int p = inc_ptr[i]; p < inc_ptr[i + 1]; ++p)
      for (int k = 0; k < 3; ++k) r.push_back(tri[inc_elem[p]][k]);
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
    adj_ptr[i + 1] = adj_ptr[i] + static_cast<int>(r.size());
  }
  adj.resize(adj_ptr.back());
  diag_pos.resize(n_nodes);
  for (int i = 0; i < n_nodes; ++i) {
    std::copy(rows[i].begin(), rows[i].end(), adj.begin() + adj_ptr[i]);
    diag_pos[i] = static_cast<int>(std::lower_bound(rows[i].begin(), rows[i].end(), i) - rows[i].begin());
  }
  pair_pos.resize(n_elems);
  for (int e = 0; e < n_elems; ++e)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        const auto& r = rows[tri[e][a]];
        pair_pos[e][a * 3 + b] =
            static_cast<int>(std::lower_bound(r.begin(), r.end(), tri[e][b]) - r.begin());
      }
  // greedy colouring in element order
  std::vector<int> color(n_elems, -1);
  std::vector<int> mark;  // per colour: last element that blocked it
  int ncol = 0;
  std::vector<char> used;
  for (int e = 0; e < n_elems; ++e) {
    used.assign(ncol + 1, 0);
    for (int k = 0; k < 3; ++k) {
      const int v = tri[e][k];
      for (int p = inc_ptr[v]; p < inc_ptr[v + 1]; ++p) {
        const int c = color[inc_elem[p]];
        if (c >= 0) used[c] = 1;
      }
    }
    int c = 0;
    while (used[c]) ++c;
    color[e] = c;
    ncol = std::max(ncol, c + 1);
  }
  colors.assign(ncol, {});
  for (int e = 0; e < n_elems; ++e) colors[color[e]].push_back(e);
  // each node's incidence ordered by colour (an element has one colour; no two elements of a
  // colour share a node, so the order is strict)
  inc_elem_by_colour.resize(inc_elem.size());
  inc_local_by_colour.resize(inc_elem.size());
  std::vector<int> order;
  for (int i = 0; i < n_nodes; ++i) {
    const int p0 = inc_ptr[i], p1 = inc_ptr[i + 1];
    order.resize(p1 - p0);
    for (int k = 0; k < p1 - p0; ++k) order[k] = p0 + k;
    std::sort(order.begin(), order.end(), [&](int u, int v) { return color[inc_elem[u]] < color[inc_elem[v]]; });
    for (int k = 0; k < p1 - p0; ++k) {
      inc_elem_by_colour[p0 + k] = inc_elem[order[k]];
      inc_local_by_colour[p0 + k] = inc_local[order[k]];
    }
  }
}

}  // namespace capsflow::shell
