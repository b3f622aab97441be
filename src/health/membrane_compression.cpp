#include "capsflow/core/health/membrane_compression.hpp"

#include <algorithm>

#include "capsflow/core/geometry/element_quality.hpp"

namespace capsflow {

MembraneCompression membrane_compression(const SurfaceMesh& reference, const Points& x, const shell::MembraneLaw& law,
                                         const Vec3& probe, double probe_radius) {
  MembraneCompression m;
  const Triangles& t = reference.triangles;
  const Points& X = reference.vertices;
  double area = 0, compressed = 0;
  for (Eigen::Index e = 0; e < t.rows(); ++e) {
    const Vec3 a = x.row(t(e, 0)), b = x.row(t(e, 1)), c = x.row(t(e, 2));
    const PrincipalStretches s = principal_stretches(X.row(t(e, 0)), X.row(t(e, 1)), X.row(t(e, 2)), a, b, c);
    double T1 = 0, T2 = 0;
    law.principal_tensions(s.l1, s.l2, T1, T2);
    const double Tmin = std::min(T1, T2) / law.Gs();
    const double ae = 0.5 * (b - a).cross(c - a).norm();
    area += ae;
    if (Tmin < -kCompressionRoundOff) compressed += ae;
    const Vec3 centroid = (a + b + c) / 3;
    if (Tmin < m.min_tension) {
      m.min_tension = Tmin;
      m.where = centroid;
    }
    if (probe_radius > 0 && Tmin < -kCompressionRoundOff && Tmin < m.min_tension_near_probe && (centroid - probe).norm() <= probe_radius)
      m.min_tension_near_probe = Tmin;
  }
  m.compressed_area_fraction = area > 0 ? compressed / area : 0;
  return m;
}

}  // namespace capsflow
