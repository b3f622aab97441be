#include "capsflow/core/mesh/generation.hpp"

#include <cmath>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include "capsflow/core/geometry/measures.hpp"

namespace capsflow {

namespace {

SurfaceMesh base_mesh(BaseSolid base) {
  SurfaceMesh m;
  if (base == BaseSolid::Octahedron) {
    m.vertices.resize(6, 3);
    m.vertices << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
    m.triangles.resize(8, 3);
    m.triangles << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  } else {
    const double p = (1.0 + std::sqrt(5.0)) / 2.0;  // golden ratio
    m.vertices.resize(12, 3);
    m.vertices << -1, p, 0, 1, p, 0, -1, -p, 0, 1, -p, 0, 0, -1, p, 0, 1, p, 0, -1, -p, 0, 1, -p,
        p, 0, -1, p, 0, 1, -p, 0, -1, -p, 0, 1;
    m.triangles.resize(20, 3);
    m.triangles << 0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2,
        10, 7, 6, 7, 1, 8, 3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10,
        8, 6, 7, 9, 8, 1;
  }
  for (Eigen::Index i = 0; i < m.vertices.rows(); ++i) m.vertices.row(i).normalize();
  return m;
}

// One 4-to-1 subdivision; midpoints shared through an edge map, then projected on the sphere.
SurfaceMesh subdivide(const SurfaceMesh& in) {
  const Eigen::Index nv = in.vertices.rows(), nt = in.triangles.rows();
  std::vector<Vec3> verts;
  verts.reserve(static_cast<size_t>(nv + 3 * nt / 2));
  for (Eigen::Index i = 0; i < nv; ++i) verts.emplace_back(in.vertices.row(i).transpose());
  std::unordered_map<long long, int> midpoint;
  midpoint.reserve(static_cast<size_t>(3 * nt));
  auto mid = [&](int a, int b) {
    const long long key = static_cast<long long>(std::min(a, b)) * nv + std::max(a, b);
    auto it = midpoint.find(key);
    if (it != midpoint.end()) return it->second;
    const int id = static_cast<int>(verts.size());
    verts.push_back((0.5 * (verts[a] + verts[b])).normalized());
    midpoint.emplace(key, id);
    return id;
  };
  SurfaceMesh out;
  out.triangles.resize(4 * nt, 3);
  for (Eigen::Index t = 0; t < nt; ++t) {
    const int a = in.triangles(t, 0), b = in.triangles(t, 1), c = in.triangles(t, 2);
    const int ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
    out.triangles.row(4 * t + 0) << a, ab, ca;
    out.triangles.row(4 * t + 1) << ab, b, bc;
    out.triangles.row(4 * t + 2) << ca, bc, c;
    out.triangles.row(4 * t + 3) << ab, bc, ca;
  }
  out.vertices.resize(static_cast<Eigen::Index>(verts.size()), 3);
  for (size_t i = 0; i < verts.size(); ++i) out.vertices.row(static_cast<Eigen::Index>(i)) = verts[i];
  return out;
}

}  // namespace

SurfaceMesh make_sphere_mesh(BaseSolid base, int level) {
  if (level < 0 || level > 10)
    throw std::invalid_argument("mesh level " + std::to_string(level) + " out of range [0, 10]");
  SurfaceMesh m = base_mesh(base);
  for (int k = 0; k < level; ++k) m = subdivide(m);
  return m;
}

void scale_to_unit_equivalent_radius(SurfaceMesh& mesh) {
  const double v = enclosed_volume(mesh);
  if (!(v > 0)) throw std::invalid_argument("mesh encloses a non-positive volume; cannot scale to ℓ = 1");
  mesh.vertices *= std::cbrt(4.0 * M_PI / (3.0 * v));
}

void map_to_spheroid(SurfaceMesh& mesh, double aspect, int axis) {
  if (!(aspect > 0) || !std::isfinite(aspect))
    throw std::invalid_argument("spheroid aspect must be a positive finite number");
  if (axis < 0 || axis > 2) throw std::invalid_argument("spheroid axis must be 1, 2 or 3");
  const double b = std::cbrt(1.0 / aspect), a = aspect * b;  // a b^2 = 1
  for (int k = 0; k < 3; ++k) mesh.vertices.col(k) *= (k == axis ? a : b);
  scale_to_unit_equivalent_radius(mesh);
}

MeshCounts expected_counts(BaseSolid base, int level) {
  const long f0 = base == BaseSolid::Icosahedron ? 20 : 8;
  const long f = f0 << (2 * level);
  const long e = 3 * f / 2;
  return {f, e - f + 2, e};  // Euler: V − E + F = 2
}

}  // namespace capsflow
