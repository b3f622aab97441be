#include "capsflow/core/bie/corner_double_layer.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace capsflow {

CornerFans::CornerFans(const Triangles& triangles, Eigen::Index n_nodes) {
  std::vector<std::vector<CornerFacet>> fan(static_cast<size_t>(n_nodes));
  for (Eigen::Index e = 0; e < triangles.rows(); ++e)
    for (int k = 0; k < 3; ++k)
      fan[static_cast<size_t>(triangles(e, k))].push_back({triangles(e, (k + 1) % 3), triangles(e, (k + 2) % 3), -1});
  start.assign(1, 0);
  for (Eigen::Index i = 0; i < n_nodes; ++i) {
    auto& f = fan[static_cast<size_t>(i)];
    for (auto& a : f)
      for (size_t b = 0; b < f.size(); ++b)
        if (f[b].p == a.q) a.next = static_cast<int>(b);
    for (const auto& a : f)
      if (a.next < 0) throw std::invalid_argument("corner double layer: the fan of node " + std::to_string(i) + " is not closed");
    facets.insert(facets.end(), f.begin(), f.end());
    start.push_back(static_cast<int>(facets.size()));
  }
}

Mat3 corner_double_layer(const Points& x, Eigen::Index i, const CornerFans& fans) {
  const Vec3 xi = x.row(i).transpose();
  const int b0 = fans.start[static_cast<size_t>(i)], b1 = fans.start[static_cast<size_t>(i) + 1];
  Vec3 normal[16];
  std::vector<Vec3> more;  // valence above 16: rare
  Vec3* n = b1 - b0 <= 16 ? normal : (more.resize(static_cast<size_t>(b1 - b0)), more.data());
  Mat3 H = Mat3::Zero();  // Σ tan(θ/2) (n (a + b)ᵀ + (a + b) nᵀ)
  for (int f = b0; f < b1; ++f) {
    const CornerFacet& F = fans.facets[static_cast<size_t>(f)];
    const Vec3 p = x.row(F.p).transpose() - xi, q = x.row(F.q).transpose() - xi;
    const Vec3 a = p.normalized(), b = q.normalized(), c = a.cross(b);
    n[f - b0] = c.normalized();
    const double tan_half = c.norm() / (1 + a.dot(b));  // tan(θ/2) = sin θ/(1 + cos θ)
    const Vec3 s = tan_half * (a + b);
    H += n[f - b0] * s.transpose() + s * n[f - b0].transpose();
  }
  double turning = 0;  // Σ ψ over the edges x → q: facet f before, its next after
  for (int f = b0; f < b1; ++f) {
    const CornerFacet& F = fans.facets[static_cast<size_t>(f)];
    const Vec3 t = (x.row(F.q).transpose() - xi).normalized();
    const Vec3& before = n[f - b0];
    const Vec3& after = n[F.next];
    turning += std::atan2(t.dot(after.cross(before)), before.dot(after));
  }
  const double solid_angle = 2 * M_PI - turning;
  return (3 / (4 * M_PI)) * ((solid_angle / 3) * Mat3::Identity() - H / 6);
}

}  // namespace capsflow
