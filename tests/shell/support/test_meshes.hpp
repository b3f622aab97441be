#pragma once
// Small meshes for the shell tests and benchmarks (the project's mesh generator lives in src/,
// which the shell may not use): icosphere, structured triangulated rectangles, and maps of the
// latter onto cylinders / spheres. All triangles are counter-clockwise seen from outside (+z for
// a flat plate in the x-y plane).
#include <array>
#include <cmath>
#include <map>
#include <vector>

#include "capsflow/shell/types.hpp"

namespace capsflow::shell::testing {

struct Mesh {
  Points X;
  Triangles T;
};

/// Icosahedron subdivided `level` times, projected on the unit sphere: 20*4^level triangles.
inline Mesh icosphere(int level) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<std::array<double, 3>> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                          {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                          {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  auto norm = [](std::array<double, 3> p) {
    const double l = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    return std::array<double, 3>{p[0] / l, p[1] / l, p[2] / l};
  };
  for (auto& p : v) p = norm(p);
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      const auto& pa = v[a];
      const auto& pb = v[b];
      v.push_back(norm({pa[0] + pb[0], pa[1] + pb[1], pa[2] + pb[2]}));
      const int id = static_cast<int>(v.size()) - 1;
      mid[key] = id;
      return id;
    };
    std::vector<std::array<int, 3>> g;
    for (auto& tr : f) {
      const int a = midpoint(tr[0], tr[1]), b = midpoint(tr[1], tr[2]), c = midpoint(tr[2], tr[0]);
      g.push_back({tr[0], a, c});
      g.push_back({tr[1], b, a});
      g.push_back({tr[2], c, b});
      g.push_back({a, b, c});
    }
    f.swap(g);
  }
  Mesh m;
  m.X.resize(v.size(), 3);
  for (size_t i = 0; i < v.size(); ++i) m.X.row(i) << v[i][0], v[i][1], v[i][2];
  m.T.resize(f.size(), 3);
  for (size_t e = 0; e < f.size(); ++e) m.T.row(e) << f[e][0], f[e][1], f[e][2];
  // orient outward
  for (Eigen::Index e = 0; e < m.T.rows(); ++e) {
    const Vec3 a = m.X.row(m.T(e, 0)), b = m.X.row(m.T(e, 1)), c = m.X.row(m.T(e, 2));
    if ((b - a).cross(c - a).dot(a + b + c) < 0) std::swap(m.T(e, 1), m.T(e, 2));
  }
  return m;
}

/// Structured grid on [0,Lx] x [0,Ly] (z = 0) with nx x ny cells, each split into 2 triangles.
/// pattern 0: all diagonals the same way; 1: alternating ("union jack"-like criss-cross free).
inline Mesh plate(double Lx, double Ly, int nx, int ny, int pattern = 0) {
  Mesh m;
  m.X.resize((nx + 1) * (ny + 1), 3);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.X.row(j * (nx + 1) + i) << Lx * i / nx, Ly * j / ny, 0.0;
  m.T.resize(2 * nx * ny, 3);
  int e = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1;
      const bool flip = pattern == 1 && ((i + j) % 2 == 1);
      if (!flip) {
        m.T.row(e++) << a, b, d;
        m.T.row(e++) << a, d, c;
      } else {
        m.T.row(e++) << a, b, c;
        m.T.row(e++) << b, d, c;
      }
    }
  return m;
}

}  // namespace capsflow::shell::testing
