#include "capsflow/core/rhs/volume_constraint.hpp"

#include <stdexcept>

#include <cmath>

#include "capsflow/core/geometry/measures.hpp"

namespace capsflow {

void volume_gradient(const Points& x, const Triangles& tri, Points& a) {
  a.setZero(x.rows(), 3);
  for (Eigen::Index e = 0; e < tri.rows(); ++e) {
    const int i = tri(e, 0), j = tri(e, 1), k = tri(e, 2);
    const Eigen::RowVector3d an = (x.row(j) - x.row(i)).cross(x.row(k) - x.row(i)) / 6.0;  // A_e n_e / 3
    a.row(i) += an, a.row(j) += an, a.row(k) += an;
  }
}

void remove_normal_flux(const Points& a, Points& v) {
  double flux = 0, weight = 0;
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    flux += a.row(i).dot(v.row(i));
    weight += a.row(i).norm();
  }
  const double c = flux / weight;
  for (Eigen::Index i = 0; i < a.rows(); ++i) v.row(i) -= c * a.row(i).normalized();
}

double project_volume(Points& x, const Triangles& tri, double target, Points& a) {
  double moved = 0;
  for (int it = 0; it < 3; ++it) {
    const double V = enclosed_volume(SurfaceMesh{x, tri});
    if (std::abs(V - target) <= 1e-14 * std::abs(target)) break;
    volume_gradient(x, tri, a);
    double weight = 0;
    for (Eigen::Index i = 0; i < a.rows(); ++i) weight += a.row(i).norm();
    const double delta = (target - V) / weight;  // dV = Σ a_i·(δ a_i/|a_i|) = δ Σ|a_i|
    for (Eigen::Index i = 0; i < a.rows(); ++i) x.row(i) += delta * a.row(i).normalized();
    moved += std::abs(delta);
  }
  return moved;
}

VolumeProjection::VolumeProjection(const SurfaceSet& surfaces, std::vector<double> targets)
    : targets_(std::move(targets)) {
  if (static_cast<int>(targets_.size()) != surfaces.size())
    throw std::invalid_argument("volume projection: one target volume per surface");
  for (int k = 0; k < surfaces.size(); ++k) {
    parts_.push_back(surfaces.part(k));
    triangles_.push_back(surfaces.local_triangles(k));
  }
}

double VolumeProjection::apply(Points& x) {
  double moved = 0;
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    part_ = x.middleRows(parts_[k].node_begin, parts_[k].nodes);
    moved += project_volume(part_, triangles_[k], targets_[k], scratch_);
    x.middleRows(parts_[k].node_begin, parts_[k].nodes) = part_;
  }
  return moved;
}

}  // namespace capsflow
