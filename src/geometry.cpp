#include "capsflow/core/geometry.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

namespace capsflow {

namespace {
inline Vec3 vertex(const SurfaceMesh& m, int i) { return m.vertices.row(i).transpose(); }
// Twice the area vector (x1 − x0) × (x2 − x0) of element e.
inline Vec3 area_vector2(const SurfaceMesh& m, Eigen::Index e) {
  const Vec3 a = vertex(m, m.triangles(e, 0)), b = vertex(m, m.triangles(e, 1)),
             c = vertex(m, m.triangles(e, 2));
  return (b - a).cross(c - a);
}
}  // namespace

Eigen::VectorXd element_areas(const SurfaceMesh& mesh) {
  Eigen::VectorXd a(mesh.num_elements());
  for (Eigen::Index e = 0; e < a.size(); ++e) a[e] = 0.5 * area_vector2(mesh, e).norm();
  return a;
}

Points element_normals(const SurfaceMesh& mesh) {
  Points n(mesh.num_elements(), 3);
  for (Eigen::Index e = 0; e < n.rows(); ++e) n.row(e) = area_vector2(mesh, e).normalized().transpose();
  return n;
}

Points nodal_normals(const SurfaceMesh& mesh) {
  Points n = Points::Zero(mesh.num_nodes(), 3);
  for (Eigen::Index e = 0; e < mesh.num_elements(); ++e) {
    const Vec3 a2 = area_vector2(mesh, e);  // area-weighted normal
    for (int k = 0; k < 3; ++k) n.row(mesh.triangles(e, k)) += a2.transpose();
  }
  for (Eigen::Index i = 0; i < n.rows(); ++i) n.row(i).normalize();
  return n;
}

Eigen::VectorXd nodal_areas(const SurfaceMesh& mesh) {
  Eigen::VectorXd a = Eigen::VectorXd::Zero(mesh.num_nodes());
  const Eigen::VectorXd ae = element_areas(mesh);
  for (Eigen::Index e = 0; e < mesh.num_elements(); ++e)
    for (int k = 0; k < 3; ++k) a[mesh.triangles(e, k)] += ae[e] / 3.0;
  return a;
}

double surface_area(const SurfaceMesh& mesh) { return element_areas(mesh).sum(); }

double enclosed_volume(const SurfaceMesh& mesh) { return volume_moments(mesh).volume; }

VolumeMoments volume_moments(const SurfaceMesh& mesh) {
  // Tetrahedra from a reference point o (the vertex mean, to limit round-off) to each facet.
  const Vec3 o = mesh.vertices.colwise().mean().transpose();
  double vol = 0;
  Vec3 first = Vec3::Zero();
  Mat3 second = Mat3::Zero();
  for (Eigen::Index e = 0; e < mesh.num_elements(); ++e) {
    const Vec3 v0 = vertex(mesh, mesh.triangles(e, 0)) - o, v1 = vertex(mesh, mesh.triangles(e, 1)) - o,
               v2 = vertex(mesh, mesh.triangles(e, 2)) - o;
    const double vt = v0.dot(v1.cross(v2)) / 6.0;
    const Vec3 s = v0 + v1 + v2;
    vol += vt;
    first += vt * s / 4.0;
    second += (vt / 20.0) * (v0 * v0.transpose() + v1 * v1.transpose() + v2 * v2.transpose() + s * s.transpose());
  }
  VolumeMoments m;
  m.volume = vol;
  const Vec3 c = first / vol;  // centroid relative to o
  m.centroid = o + c;
  m.second_moment = second - vol * c * c.transpose();
  return m;
}

InertiaEllipsoid inertia_ellipsoid(const SurfaceMesh& mesh) {
  const VolumeMoments vm = volume_moments(mesh);
  Eigen::SelfAdjointEigenSolver<Mat3> eig(vm.second_moment);
  const Vec3 sigma = eig.eigenvalues();
  const Mat3 vec = eig.eigenvectors();
  // Assign each principal axis to the coordinate axis it is most aligned with (greedy on |cos|).
  InertiaEllipsoid out;
  out.centroid = vm.centroid;
  std::array<bool, 3> used_axis{false, false, false}, used_vec{false, false, false};
  for (int round = 0; round < 3; ++round) {
    int best_i = -1, best_k = -1;
    double best = -1;
    for (int k = 0; k < 3; ++k) {
      if (used_vec[k]) continue;
      for (int i = 0; i < 3; ++i)
        if (!used_axis[i] && std::abs(vec(i, k)) > best) best = std::abs(vec(i, k)), best_i = i, best_k = k;
    }
    used_axis[best_i] = used_vec[best_k] = true;
    out.semi_axes[best_i] = std::sqrt(5.0 * std::max(sigma[best_k], 0.0) / vm.volume);
    Vec3 dir = vec.col(best_k);
    if (dir[best_i] < 0) dir = -dir;
    out.axes.col(best_i) = dir;
  }
  return out;
}

TaylorDeformation taylor_deformation(const InertiaEllipsoid& e) {
  const Vec3& L = e.semi_axes;
  auto d = [](double a, double b) { return (a - b) / (a + b); };
  return {d(L[0], L[1]), d(L[0], L[2]), d(L[1], L[2])};
}

Vec3 half_extents(const SurfaceMesh& mesh) {
  return 0.5 * (mesh.vertices.colwise().maxCoeff() - mesh.vertices.colwise().minCoeff()).transpose();
}

Eigen::SparseMatrix<double> mass_matrix(const SurfaceMesh& mesh) {
  const Eigen::VectorXd area = element_areas(mesh);
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(static_cast<size_t>(9 * mesh.num_elements()));
  for (Eigen::Index e = 0; e < mesh.num_elements(); ++e)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        trip.emplace_back(mesh.triangles(e, a), mesh.triangles(e, b), area[e] / 12.0 * (a == b ? 2.0 : 1.0));
  Eigen::SparseMatrix<double> m(mesh.num_nodes(), mesh.num_nodes());
  m.setFromTriplets(trip.begin(), trip.end());
  return m;
}

}  // namespace capsflow
