#include "capsflow/core/geometry/measures.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "capsflow/shell/director.hpp"

namespace capsflow {

namespace {
// Twice the area vector (x1 − x0) × (x2 − x0) of element e.
inline Vec3 area_vector2(const Points& x, const Triangles& t, Eigen::Index e) {
  const Vec3 a = x.row(t(e, 0)).transpose(), b = x.row(t(e, 1)).transpose(), c = x.row(t(e, 2)).transpose();
  return (b - a).cross(c - a);
}
inline Vec3 area_vector2(const SurfaceMesh& m, Eigen::Index e) { return area_vector2(m.vertices, m.triangles, e); }
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
  return shell::area_weighted_normals(mesh.vertices, mesh.triangles);  // the wall's directors' formula
}

Eigen::VectorXd nodal_areas(const SurfaceMesh& mesh) { return nodal_areas(mesh.vertices, mesh.triangles); }

Eigen::VectorXd nodal_areas(const Points& x, const Triangles& triangles) {
  Eigen::VectorXd a = Eigen::VectorXd::Zero(x.rows());
  for (Eigen::Index e = 0; e < triangles.rows(); ++e) {
    const double ae = 0.5 * area_vector2(x, triangles, e).norm();
    for (int k = 0; k < 3; ++k) a[triangles(e, k)] += ae / 3.0;
  }
  return a;
}

double surface_area(const SurfaceMesh& mesh) { return element_areas(mesh).sum(); }

double enclosed_volume(const SurfaceMesh& mesh) { return volume_moments(mesh).volume; }

VolumeMoments volume_moments(const SurfaceMesh& mesh) { return volume_moments(mesh.vertices, mesh.triangles); }

VolumeMoments volume_moments(const Points& x, const Triangles& triangles) {
  // Tetrahedra from a reference point o (the vertex mean, to limit round-off) to each facet.
  const Vec3 o = x.colwise().mean().transpose();
  double vol = 0;
  Vec3 first = Vec3::Zero();
  Mat3 second = Mat3::Zero();
  for (Eigen::Index e = 0; e < triangles.rows(); ++e) {
    const Vec3 v0 = x.row(triangles(e, 0)).transpose() - o, v1 = x.row(triangles(e, 1)).transpose() - o,
               v2 = x.row(triangles(e, 2)).transpose() - o;
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

Vec3 centroid_rate(const Points& x, const Triangles& triangles, const Points& v) {
  // c = o + F/V over the tetrahedra (o, facet) as in volume_moments; o is held fixed (c does not
  // depend on it), so dc = (dF − (F/V) dV)/V with each tetrahedron's dV and dF along v.
  const Vec3 o = x.colwise().mean().transpose();
  double vol = 0, dvol = 0;
  Vec3 first = Vec3::Zero(), dfirst = Vec3::Zero();
  for (Eigen::Index e = 0; e < triangles.rows(); ++e) {
    const Vec3 a = x.row(triangles(e, 0)).transpose() - o, b = x.row(triangles(e, 1)).transpose() - o,
               c = x.row(triangles(e, 2)).transpose() - o;
    const Vec3 wa = v.row(triangles(e, 0)).transpose(), wb = v.row(triangles(e, 1)).transpose(),
               wc = v.row(triangles(e, 2)).transpose();
    const double vt = a.dot(b.cross(c)) / 6.0;
    const double dvt = (wa.dot(b.cross(c)) + a.dot(wb.cross(c)) + a.dot(b.cross(wc))) / 6.0;
    vol += vt;
    dvol += dvt;
    first += vt * (a + b + c) / 4.0;
    dfirst += (dvt * (a + b + c) + vt * (wa + wb + wc)) / 4.0;
  }
  return (dfirst - (first / vol) * dvol) / vol;
}

Vec3 half_extents(const SurfaceMesh& mesh) {
  return 0.5 * (mesh.vertices.colwise().maxCoeff() - mesh.vertices.colwise().minCoeff()).transpose();
}

}  // namespace capsflow
