#include "capsflow/core/geometry/surface_roughness.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace capsflow {

double quantile(std::vector<double>& values, double q) {
  if (values.empty()) return 0;
  const auto k = static_cast<std::ptrdiff_t>(std::lround(q * static_cast<double>(values.size() - 1)));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[static_cast<size_t>(k)];
}

RoughnessMeter::RoughnessMeter(const Triangles& triangles, Eigen::Index num_nodes)
    : tri_(triangles), umbrella_(triangles, num_nodes) {
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
  const Eigen::Index ne = tri_.rows(), n = x.rows();
  Points fn(ne, 3);
  for (Eigen::Index e = 0; e < ne; ++e) {
    const Vec3 a = x.row(tri_(e, 0)), b = x.row(tri_(e, 1)), c = x.row(tri_(e, 2));
    fn.row(e) = (b - a).cross(c - a).transpose();
  }
  // Area-weighted vertex normals (the unnormalised facet normals carry twice the area).
  normals_.setZero(n, 3);
  for (Eigen::Index e = 0; e < ne; ++e)
    for (int k = 0; k < 3; ++k) normals_.row(tri_(e, k)) += fn.row(e);
  normals_.rowwise().normalize();
  fn.rowwise().normalize();

  std::vector<double> angles(edge_faces_.size());
  for (size_t k = 0; k < edge_faces_.size(); ++k) {
    const double cosang = std::clamp(fn.row(edge_faces_[k][0]).dot(fn.row(edge_faces_[k][1])), -1.0, 1.0);
    angles[k] = std::acos(cosang) * 180.0 / M_PI;
  }
  r.facet_angle_max = angles.empty() ? 0 : *std::max_element(angles.begin(), angles.end());
  r.facet_angle_p99 = quantile(angles, 0.99);

  umbrella_.apply(x, ux_);
  c_ = (ux_.array() * normals_.array()).rowwise().sum();
  scratch_ = Points::Zero(n, 3);
  scratch_.col(0) = c_;
  umbrella_.apply(scratch_, ux_);  // (U c) in column 0
  std::vector<double> osc(static_cast<size_t>(n));
  const auto& off = umbrella_.offsets();
  const auto& nb = umbrella_.neighbours();
  Eigen::Index worst = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    double h = 0;
    for (int k = off[i]; k < off[i + 1]; ++k) h += (x.row(nb[k]) - x.row(i)).norm();
    const int deg = off[i + 1] - off[i];
    h = deg > 0 ? h / deg : 0;
    osc[i] = h > 0 ? std::abs(ux_(i, 0)) / h : 0;
    if (osc[i] > osc[worst]) worst = i;
  }
  r.grid_oscillation_max = n ? osc[worst] : 0;
  r.worst_position = n ? Vec3(x.row(worst).transpose()) : Vec3::Zero();
  r.grid_oscillation_p99 = quantile(osc, 0.99);
  return r;
}

}  // namespace capsflow
