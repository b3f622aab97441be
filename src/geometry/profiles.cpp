#include "capsflow/core/geometry/profiles.hpp"

#include <map>
#include <unordered_map>

namespace capsflow {

const char* to_string(CoordinatePlane p) {
  switch (p) {
    case CoordinatePlane::X1X2: return "x1x2";
    case CoordinatePlane::X1X3: return "x1x3";
    default: return "x2x3";
  }
}

std::vector<Polyline> cross_section(const SurfaceMesh& mesh, CoordinatePlane plane, const Vec3& origin) {
  const int axis = plane == CoordinatePlane::X1X2 ? 2 : (plane == CoordinatePlane::X1X3 ? 1 : 0);
  const long long n = mesh.num_nodes();
  auto side = [&](int v) { return mesh.vertices(v, axis) - origin[axis] >= 0; };
  auto key = [n](int a, int b) { return a < b ? a * n + b : b * n + a; };
  auto crossing_point = [&](int a, int b) {
    const double da = mesh.vertices(a, axis) - origin[axis], db = mesh.vertices(b, axis) - origin[axis];
    const double t = da / (da - db);
    Vec3 p = ((1 - t) * mesh.vertices.row(a) + t * mesh.vertices.row(b)).transpose();
    p[axis] = origin[axis];
    return p;
  };
  // Each crossed element gives a segment between two crossed edges; link segments by edge.
  std::map<long long, std::vector<long long>> links;  // edge key -> neighbour edge keys (ordered: deterministic output)
  std::unordered_map<long long, Vec3> point;
  for (Eigen::Index e = 0; e < mesh.num_elements(); ++e) {
    long long ends[2];
    int m = 0;
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.triangles(e, k), b = mesh.triangles(e, (k + 1) % 3);
      if (side(a) != side(b)) {
        const long long kk = key(a, b);
        if (!point.count(kk)) point.emplace(kk, crossing_point(a, b));
        ends[m++] = kk;
      }
    }
    if (m == 2) {
      links[ends[0]].push_back(ends[1]);
      links[ends[1]].push_back(ends[0]);
    }
  }
  std::vector<Polyline> out;
  std::unordered_map<long long, bool> used;
  for (const auto& [start, nb] : links) {
    if (used[start]) continue;
    Polyline pl;
    long long prev = -1, cur = start;
    for (;;) {
      used[cur] = true;
      // A vertex lying on the plane is the crossing point of all its edges to the negative
      // side: keep one copy.
      const Vec3& p = point.at(cur);
      if (pl.points.empty() || (p - pl.points.back()).norm() > 1e-14 * (1 + p.norm())) pl.points.push_back(p);
      long long next = -1;
      for (long long c : links[cur])
        if (c != prev && !used[c]) { next = c; break; }
      if (next < 0) {
        for (long long c : links[cur])
          if (c == start && c != prev) pl.closed = true;
        break;
      }
      prev = cur;
      cur = next;
    }
    if (pl.closed) {
      if ((pl.points.back() - pl.points.front()).norm() <= 1e-14 * (1 + pl.points.front().norm())) pl.points.pop_back();
      pl.points.push_back(pl.points.front());
    }
    out.push_back(std::move(pl));
  }
  return out;
}

}  // namespace capsflow
