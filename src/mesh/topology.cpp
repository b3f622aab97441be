#include "capsflow/core/mesh/topology.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <unordered_map>
#include <vector>

#include "capsflow/core/geometry/measures.hpp"

namespace capsflow {

namespace {
inline long long edge_key(int a, int b, long long n) { return static_cast<long long>(a) * n + b; }
std::string tri_str(const SurfaceMesh& m, Eigen::Index e) {
  return "element " + std::to_string(e) + " (" + std::to_string(m.triangles(e, 0)) + ", " +
         std::to_string(m.triangles(e, 1)) + ", " + std::to_string(m.triangles(e, 2)) + ")";
}

// Number of vertices whose coordinates equal another vertex's exactly: a triangle soup (every
// triangle with its own three vertices, as STL converters write) has all of them duplicated.
long count_duplicate_positions(const SurfaceMesh& m) {
  std::vector<Eigen::Index> order(static_cast<size_t>(m.num_nodes()));
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<Eigen::Index>(i);
  auto less = [&](Eigen::Index a, Eigen::Index b) {
    for (int k = 0; k < 3; ++k)
      if (m.vertices(a, k) != m.vertices(b, k)) return m.vertices(a, k) < m.vertices(b, k);
    return false;
  };
  std::sort(order.begin(), order.end(), less);
  long dup = 0;
  for (size_t i = 0; i < order.size(); ++i) {
    const bool same_prev = i > 0 && !less(order[i - 1], order[i]);
    const bool same_next = i + 1 < order.size() && !less(order[i], order[i + 1]);
    if (same_prev || same_next) ++dup;
  }
  return dup;
}

std::string soup_hint(const SurfaceMesh& m) {
  const long dup = count_duplicate_positions(m);
  if (dup == 0) return "";
  return "; " + std::to_string(dup) + " of the " + std::to_string(m.num_nodes()) +
         " vertices share their position with another vertex: merge duplicate vertices (a triangle soup, e.g. converted "
         "from STL; MeshLab 'Merge Close Vertices', trimesh merge_vertices) and try again";
}

// Two distinct vertices at (nearly) the same place: the surface is pinched or touches itself
// there, although every topological check passes. Returns the first such pair, or (-1, -1).
// Candidates come from a sweep over x; `tol` is absolute.
std::pair<Eigen::Index, Eigen::Index> coincident_vertices(const SurfaceMesh& m, double tol) {
  std::vector<Eigen::Index> order(static_cast<size_t>(m.num_nodes()));
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<Eigen::Index>(i);
  std::sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) { return m.vertices(a, 0) < m.vertices(b, 0); });
  for (size_t i = 0; i < order.size(); ++i)
    for (size_t j = i + 1; j < order.size() && m.vertices(order[j], 0) - m.vertices(order[i], 0) <= tol; ++j)
      if ((m.vertices.row(order[i]) - m.vertices.row(order[j])).norm() <= tol)
        return {std::min(order[i], order[j]), std::max(order[i], order[j])};
  return {-1, -1};
}

}  // namespace

Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor> mesh_edges(const SurfaceMesh& mesh) {
  const long long n = mesh.num_nodes();
  std::unordered_map<long long, int> seen;
  std::vector<std::array<int, 2>> edges;
  for (Eigen::Index e = 0; e < mesh.num_elements(); ++e)
    for (int k = 0; k < 3; ++k) {
      int a = mesh.triangles(e, k), b = mesh.triangles(e, (k + 1) % 3);
      if (a > b) std::swap(a, b);
      if (seen.emplace(edge_key(a, b, n), static_cast<int>(edges.size())).second) edges.push_back({a, b});
    }
  Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor> out(static_cast<Eigen::Index>(edges.size()), 2);
  for (size_t i = 0; i < edges.size(); ++i) out.row(static_cast<Eigen::Index>(i)) << edges[i][0], edges[i][1];
  return out;
}

bool validate_closed_surface(SurfaceMesh& mesh) {
  const Eigen::Index nv = mesh.num_nodes(), nt = mesh.num_elements();
  if (nt < 4 || nv < 4) throw MeshError("mesh has " + std::to_string(nt) + " elements and " +
                                        std::to_string(nv) + " vertices; a closed surface needs at least 4 of each");
  for (Eigen::Index i = 0; i < nv; ++i)
    if (!mesh.vertices.row(i).allFinite())
      throw MeshError("vertex " + std::to_string(i) + " has a non-finite coordinate");
  std::vector<int> used(static_cast<size_t>(nv), 0);
  for (Eigen::Index e = 0; e < nt; ++e) {
    const int a = mesh.triangles(e, 0), b = mesh.triangles(e, 1), c = mesh.triangles(e, 2);
    for (int v : {a, b, c})
      if (v < 0 || v >= nv) throw MeshError(tri_str(mesh, e) + " references a vertex index out of range [0, " + std::to_string(nv) + ")");
    if (a == b || b == c || c == a) throw MeshError(tri_str(mesh, e) + " repeats a vertex (degenerate)");
    used[a] = used[b] = used[c] = 1;
  }
  for (Eigen::Index i = 0; i < nv; ++i)
    if (!used[i]) throw MeshError("vertex " + std::to_string(i) + " is not used by any element");

  // Directed edges: each must appear exactly once, and its reverse exactly once.
  std::unordered_map<long long, Eigen::Index> directed;
  directed.reserve(static_cast<size_t>(3 * nt));
  for (Eigen::Index e = 0; e < nt; ++e)
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.triangles(e, k), b = mesh.triangles(e, (k + 1) % 3);
      auto [it, fresh] = directed.emplace(edge_key(a, b, nv), e);
      if (!fresh) {
        // The same directed edge twice: either a non-manifold edge (≥ 3 elements) or two
        // neighbours with opposite orientation.
        int count = 0;
        for (Eigen::Index f = 0; f < nt; ++f)
          for (int j = 0; j < 3; ++j) {
            const int p = mesh.triangles(f, j), q = mesh.triangles(f, (j + 1) % 3);
            if ((p == a && q == b) || (p == b && q == a)) ++count;
          }
        if (count > 2)
          throw MeshError("non-manifold edge (" + std::to_string(a) + ", " + std::to_string(b) + ") shared by " +
                          std::to_string(count) + " elements, first offending " + tri_str(mesh, e));
        throw MeshError("inconsistent orientation: " + tri_str(mesh, e) + " and element " +
                        std::to_string(it->second) + " traverse edge (" + std::to_string(a) + ", " +
                        std::to_string(b) + ") in the same direction");
      }
    }
  for (Eigen::Index e = 0; e < nt; ++e)
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.triangles(e, k), b = mesh.triangles(e, (k + 1) % 3);
      if (!directed.count(edge_key(b, a, nv)))
        throw MeshError("mesh is not closed: edge (" + std::to_string(a) + ", " + std::to_string(b) + ") of " +
                        tri_str(mesh, e) + " is a boundary edge" + soup_hint(mesh));
    }

  // Vertex manifoldness: the elements around each vertex form one fan (a single cycle of the
  // "next element around the vertex" map).
  std::vector<int> valence(static_cast<size_t>(nv), 0);
  for (Eigen::Index e = 0; e < nt; ++e)
    for (int k = 0; k < 3; ++k) ++valence[mesh.triangles(e, k)];
  std::unordered_map<long long, Eigen::Index> corner;  // (vertex, next vertex) -> element
  for (Eigen::Index e = 0; e < nt; ++e)
    for (int k = 0; k < 3; ++k) corner.emplace(edge_key(mesh.triangles(e, k), mesh.triangles(e, (k + 1) % 3), nv), e);
  std::vector<char> visited_vertex(static_cast<size_t>(nv), 0);
  for (Eigen::Index e0 = 0; e0 < nt; ++e0)
    for (int k0 = 0; k0 < 3; ++k0) {
      const int v = mesh.triangles(e0, k0);
      if (visited_vertex[v]) continue;
      visited_vertex[v] = 1;
      int fan = 0;
      Eigen::Index e = e0;
      int k = k0;
      do {
        ++fan;
        const int prev = mesh.triangles(e, (k + 2) % 3);  // edge (prev, v) in e; its twin is (v, prev)
        e = corner.at(edge_key(v, prev, nv));
        k = mesh.triangles(e, 0) == v ? 0 : (mesh.triangles(e, 1) == v ? 1 : 2);
      } while (e != e0 && fan <= valence[v]);
      if (fan != valence[v])
        throw MeshError("non-manifold vertex " + std::to_string(v) + ": its " + std::to_string(valence[v]) +
                        " elements form more than one fan (first offending " + tri_str(mesh, e0) + ")");
    }

  // Coordinates so large or small that areas and volumes over- or underflow (a mesh written in
  // the wrong units by 1e±300) would be reported below as degenerate elements: name the scale.
  {
    const double extent = (mesh.vertices.colwise().maxCoeff() - mesh.vertices.colwise().minCoeff()).maxCoeff();
    if (!(extent >= 1e-100 && extent <= 1e100))
      throw MeshError(fmt::format("the mesh spans {:.3g} in its largest coordinate direction, outside [1e-100, 1e100] where "
                                  "areas and volumes are representable in double precision; rescale the mesh (capsflow "
                                  "scales it to unit equivalent radius itself)",
                                  extent));
  }

  // Degenerate (zero-area) elements.
  const Eigen::VectorXd area = element_areas(mesh);
  const double mean_area = area.mean();
  for (Eigen::Index e = 0; e < nt; ++e)
    if (!(area[e] > 1e-14 * mean_area)) throw MeshError(tri_str(mesh, e) + " has zero area (degenerate)");

  // Pinched or self-touching surface: distinct vertices at the same place. 1e-6 of the mean edge
  // is far below any element a run can resolve (its stable step would be ~1e-6 of the usual).
  {
    double mean_edge = 0;
    for (Eigen::Index e = 0; e < nt; ++e)
      for (int k = 0; k < 3; ++k)
        mean_edge += (mesh.vertices.row(mesh.triangles(e, k)) - mesh.vertices.row(mesh.triangles(e, (k + 1) % 3))).norm();
    mean_edge /= static_cast<double>(3 * nt);
    const auto [i, j] = coincident_vertices(mesh, 1e-6 * mean_edge);
    if (i >= 0)
      throw MeshError("vertices " + std::to_string(i) + " and " + std::to_string(j) +
                      " are at the same position: the surface is pinched or touches itself there" +
                      (count_duplicate_positions(mesh) > 2 ? soup_hint(mesh) : std::string()));
  }

  // Sphere topology: one connected component and χ = V − E + F = 2.
  std::vector<int> parent(static_cast<size_t>(nv));
  for (Eigen::Index i = 0; i < nv; ++i) parent[i] = static_cast<int>(i);
  auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (Eigen::Index e = 0; e < nt; ++e)
    for (int k = 1; k < 3; ++k) parent[root(mesh.triangles(e, k))] = root(mesh.triangles(e, 0));
  for (Eigen::Index i = 1; i < nv; ++i)
    if (root(static_cast<int>(i)) != root(0))
      throw MeshError("mesh has more than one connected component (vertex " + std::to_string(i) +
                      " is not connected to vertex 0); a capsule wall must be one closed surface");
  const long ne = 3 * nt / 2;
  const long chi = nv - ne + nt;
  if (chi != 2)
    throw MeshError("Euler characteristic V - E + F = " + std::to_string(chi) +
                    " (expected 2): the surface has handles or several components; a capsule wall must be one closed sphere-like surface");

  if (enclosed_volume(mesh) < 0) {
    mesh.triangles.col(1).swap(mesh.triangles.col(2));
    return true;
  }
  return false;
}

}  // namespace capsflow
