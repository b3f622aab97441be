#include "capsflow/core/geometry/surface_roughness.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/shell/director.hpp"

namespace capsflow {

double quantile(std::vector<double>& values, double q) {
  if (values.empty()) return 0;
  const auto k = static_cast<std::ptrdiff_t>(std::lround(q * static_cast<double>(values.size() - 1)));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[static_cast<size_t>(k)];
}

RoughnessMeter::RoughnessMeter(const Triangles& triangles, Eigen::Index num_nodes)
    : tri_(triangles), topo_(triangles, num_nodes), umbrella_(triangles, num_nodes) {
  std::map<std::pair<int, int>, int> first;
  for (Eigen::Index e = 0; e < tri_.rows(); ++e)
    for (int k = 0; k < 3; ++k) {
      const int a = tri_(e, k), b = tri_(e, (k + 1) % 3);
      const auto key = std::minmax(a, b);
      const auto [it, inserted] = first.emplace(key, static_cast<int>(e));
      if (!inserted) edge_faces_.push_back({it->second, static_cast<int>(e)});
    }
}

SurfaceRoughness RoughnessMeter::measure(const Points& x) const {
  SurfaceRoughness r;
  const Eigen::Index n = x.rows();
  const SurfaceMesh mesh{x, tri_};
  const Points fn = element_normals(mesh);
  shell::area_weighted_normals(x, topo_, normals_);

  angles_.resize(edge_faces_.size());
  for (size_t k = 0; k < edge_faces_.size(); ++k) {
    const double cosang = std::clamp(fn.row(edge_faces_[k][0]).dot(fn.row(edge_faces_[k][1])), -1.0, 1.0);
    angles_[k] = std::acos(cosang) * 180.0 / M_PI;
  }
  r.facet_angle_max = angles_.empty() ? 0 : *std::max_element(angles_.begin(), angles_.end());
  r.facet_angle_p99 = quantile(angles_, 0.99);

  umbrella_.apply(x, ux_);
  c_ = (ux_.array() * normals_.array()).rowwise().sum();
  umbrella_.apply(c_, uc_);
  osc_.resize(static_cast<size_t>(n));
  const auto& off = umbrella_.offsets();
  const auto& nb = umbrella_.neighbours();
  Eigen::Index worst = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    double h = 0;
    for (int k = off[i]; k < off[i + 1]; ++k) h += (x.row(nb[k]) - x.row(i)).norm();
    const int deg = off[i + 1] - off[i];
    h = deg > 0 ? h / deg : 0;
    osc_[i] = h > 0 ? std::abs(uc_[i]) / h : 0;
    if (osc_[i] > osc_[worst]) worst = i;
  }
  r.grid_oscillation_max = n ? osc_[worst] : 0;
  r.worst_position = n ? Vec3(x.row(worst).transpose()) : Vec3::Zero();
  r.grid_oscillation_p99 = quantile(osc_, 0.99);
  return r;
}

}  // namespace capsflow
