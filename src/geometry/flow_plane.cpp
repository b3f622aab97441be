#include "capsflow/core/geometry/flow_plane.hpp"

#include <cmath>

#include <Eigen/Eigenvalues>

#include "capsflow/core/geometry/measures.hpp"

namespace capsflow {

FlowPlane flow_plane(const Mat3& L) {
  FlowPlane p;
  if (L.norm() == 0) return p;  // no flow: the x1x2 plane
  const Eigen::SelfAdjointEigenSolver<Mat3> es(L.transpose() * L + L * L.transpose());
  Vec3 n = es.eigenvectors().col(0);  // smallest eigenvalue: the neutral direction
  Eigen::Index k;
  n.cwiseAbs().maxCoeff(&k);
  if (n[k] < 0) n = -n;
  Vec3 e1 = Vec3::UnitX() - n.x() * n;
  if (e1.norm() < 1e-6) e1 = Vec3::UnitY() - n.y() * n;
  p.normal = n;
  p.e1 = e1.normalized();
  p.e2 = n.cross(p.e1);
  const Vec3 vorticity(L(2, 1) - L(1, 2), L(0, 2) - L(2, 0), L(1, 0) - L(0, 1));
  p.sense = vorticity.dot(n) < 0 ? -1.0 : 1.0;
  return p;
}

InPlaneShape in_plane_shape(const SurfaceMesh& mesh, const FlowPlane& plane) {
  const VolumeMoments vm = volume_moments(mesh);
  Eigen::Matrix<double, 3, 2> E;
  E << plane.e1, plane.e2;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(E.transpose() * vm.second_moment * E);
  InPlaneShape s;
  s.centroid = vm.centroid;
  s.a = std::sqrt(5 * std::max(es.eigenvalues()[1], 0.0) / vm.volume);
  s.b = std::sqrt(5 * std::max(es.eigenvalues()[0], 0.0) / vm.volume);
  s.D = (s.a - s.b) / (s.a + s.b);
  const Eigen::Vector2d major = es.eigenvectors().col(1);
  s.theta = std::atan2(major.y(), major.x());
  if (s.theta > M_PI / 2) s.theta -= M_PI;
  if (s.theta <= -M_PI / 2) s.theta += M_PI;
  return s;
}

double TankTreadingMeter::update(const SurfaceMesh& mesh, double t) {
  const InPlaneShape s = in_plane_shape(mesh, plane_);
  const Eigen::Index n = mesh.vertices.rows();
  Eigen::VectorXd phase(n), weight(n);
  const double c = std::cos(s.theta), sn = std::sin(s.theta);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Vec3 d = mesh.vertices.row(i).transpose() - s.centroid;
    const double p = d.dot(plane_.e1), q = d.dot(plane_.e2);
    const double xi = (c * p + sn * q) / s.a, eta = (-sn * p + c * q) / s.b;
    phase[i] = s.theta + std::atan2(eta, xi);
    weight[i] = xi * xi + eta * eta;
  }
  double rate = std::numeric_limits<double>::quiet_NaN();
  if (phase_.size() == n && t > t_) {
    double sum = 0, wsum = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double d = std::remainder(phase[i] - phase_[i], 2 * M_PI);  // wrapped to [−π, π]
      const double w = weight[i] * weight_[i];
      sum += w * d, wsum += w;
    }
    rate = plane_.sense * sum / (wsum * (t - t_));
  }
  phase_.swap(phase), weight_.swap(weight);
  t_ = t;
  return rate;
}

}  // namespace capsflow
