#include "capsflow/core/geometry/element_quality.hpp"

#include <algorithm>
#include <cmath>

namespace capsflow {

PrincipalStretches principal_stretches(const Vec3& A, const Vec3& B, const Vec3& C, const Vec3& a, const Vec3& b,
                                       const Vec3& c) {
  const Vec3 E1 = B - A, E2 = C - A, e1 = b - a, e2 = c - a;
  Eigen::Matrix2d G, g;
  G << E1.dot(E1), E1.dot(E2), E1.dot(E2), E2.dot(E2);
  g << e1.dot(e1), e1.dot(e2), e1.dot(e2), e2.dot(e2);
  // Eigenvalues of G⁻¹g from det(g − μ G) = 0: a quadratic with real non-negative roots.
  const double detG = G.determinant(), detg = g.determinant();
  const double tr = (G(1, 1) * g(0, 0) + G(0, 0) * g(1, 1) - 2 * G(0, 1) * g(0, 1)) / detG;
  const double det = detg / detG;
  const double disc = std::sqrt(std::max(0.0, tr * tr / 4 - det));
  const double mu1 = tr / 2 + disc, mu2 = std::max(0.0, tr / 2 - disc);
  return {std::sqrt(mu1), std::sqrt(mu2)};
}

ElementQuality element_quality(const SurfaceMesh& reference, const Points& x) {
  ElementQuality q;
  const Triangles& t = reference.triangles;
  for (Eigen::Index e = 0; e < t.rows(); ++e) {
    const Vec3 a = x.row(t(e, 0)), b = x.row(t(e, 1)), c = x.row(t(e, 2));
    const double la = (c - b).norm(), lb = (a - c).norm(), lc = (b - a).norm();
    // Interior angles from the law of cosines; the smallest is opposite the shortest edge.
    const double lmin = std::min({la, lb, lc}), lmax = std::max({la, lb, lc});
    const double other1 = la + lb + lc - lmin - lmax;
    const double cosmin = std::clamp((lmax * lmax + other1 * other1 - lmin * lmin) / (2 * lmax * other1), -1.0, 1.0);
    q.min_angle_deg = std::min(q.min_angle_deg, std::acos(cosmin) * 180.0 / M_PI);
    const double area = 0.5 * (b - a).cross(c - a).norm(), s = 0.5 * (la + lb + lc);
    const double inradius = area / s;
    q.max_aspect_ratio = std::max(q.max_aspect_ratio, inradius > 0 ? lmax / (2 * std::sqrt(3.0) * inradius) : INFINITY);
    const PrincipalStretches ps = principal_stretches(reference.vertices.row(t(e, 0)), reference.vertices.row(t(e, 1)),
                                                      reference.vertices.row(t(e, 2)), a, b, c);
    q.max_stretch = std::max(q.max_stretch, ps.l1);
    q.min_stretch = std::min(q.min_stretch, ps.l2);
    q.max_stretch_ratio = std::max(q.max_stretch_ratio, ps.l2 > 0 ? ps.l1 / ps.l2 : INFINITY);
  }
  return q;
}

}  // namespace capsflow
