#pragma once
// Nodal directors: the one place for the formulas of the director field (docs/shell.md §1.1,
// §2.8.1–2.8.2), used by the capsule wall, the forward static mode and core's geometry.
//  * Area-weighted nodal normals: at each node the normalised sum of (x1 − x0) × (x2 − x0) over
//    its elements, in element order (the reference directors, the predictor's normals, and
//    capsflow::nodal_normals).
//  * Nodal triads (t1, t2, d), right-handed: t1 × t2 = d, shared by all elements around a node.
//    Built from d by Gram–Schmidt (tangent_basis); turned by increments with Rodrigues' formula
//    (exact for any angle), the same rotation carrying t1 and t2, so the triad stays orthonormal.
#include "capsflow/shell/topology.hpp"
#include "capsflow/shell/types.hpp"

namespace capsflow::shell {

/// exp([w]x) v  (Rodrigues; exact for any |w|).
inline Vec3 rodrigues(const Vec3& w, const Vec3& v) {
  const double t2 = w.squaredNorm();
  if (t2 < 1e-30) return v + w.cross(v);
  const double t = std::sqrt(t2);
  const Vec3 k = w / t;
  const double c = std::cos(t), s = std::sin(t);
  return c * v + s * k.cross(v) + (1.0 - c) * k.dot(v) * k;
}

/// The smallest rotation vector w with exp([w]x) a = b (a, b unit vectors). False when a × b
/// vanishes (|a × b| < 1e-15): no rotation to apply.
inline bool minimal_rotation(const Vec3& a, const Vec3& b, Vec3& w) {
  const Vec3 ax = a.cross(b);
  const double s = ax.norm(), c = a.dot(b);
  if (s < 1e-15) return false;
  w = ax * (std::atan2(s, c) / s);
  return true;
}

/// t1 from the coordinate axis least aligned with d (Gram-Schmidt), t2 = d x t1.
void tangent_basis(const Vec3& d, Vec3& t1, Vec3& t2);

/// One triad (t1, t2, d) per node, as rows of N×3 arrays.
struct NodalTriads {
  Points d, t1, t2;

  NodalTriads() = default;
  /// The triads of the given directors (each normalised), t1 and t2 from tangent_basis.
  explicit NodalTriads(const Points& directors);
  Eigen::Index size() const { return d.rows(); }
  /// Turns the triad of node i by exp([w]x): d and t1 rotated with Rodrigues, d normalised, t1
  /// made orthogonal to d and normalised, t2 = d x t1 (orthonormal to round-off).
  void rotate(Eigen::Index i, const Vec3& w) {
    const Vec3 dn = rodrigues(w, Vec3(d.row(i))).normalized();
    Vec3 an = rodrigues(w, Vec3(t1.row(i)));
    an = (an - an.dot(dn) * dn).normalized();
    d.row(i) = dn;
    t1.row(i) = an;
    t2.row(i) = dn.cross(an);
  }
};

/// Area-weighted nodal normals of the surface x (unit vectors; a node whose area vectors sum to
/// zero keeps the zero vector). Each node sums its own elements: parallel, bit-identical for any
/// thread count, no allocation once n is sized.
void area_weighted_normals(const Points& x, const Topology& topo, Points& n);
/// Node i's row of area_weighted_normals (the same arithmetic).
inline Vec3 area_weighted_normal(const Points& x, const Topology& topo, int i) {
  Vec3 s = Vec3::Zero();
  for (int p = topo.inc_ptr[i]; p < topo.inc_ptr[i + 1]; ++p) {
    const auto& t = topo.tri[topo.inc_elem[p]];
    const Vec3 a = x.row(t[0]);
    s += (Vec3(x.row(t[1])) - a).cross(Vec3(x.row(t[2])) - a);
  }
  return s.normalized();
}
/// The same for a bare triangle list (builds the node–element incidence on each call: keep a
/// Topology for repeated calls).
Points area_weighted_normals(const Points& x, const Triangles& tri);

}  // namespace capsflow::shell
