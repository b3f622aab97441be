#pragma once
// Nodal directors and their tangent triads (t1, t2, d), right-handed: t1 x t2 = d.
// Rotations are applied incrementally with Rodrigues' formula (exact for any angle), and the same
// rotation transports t1, t2, so the triad stays nodal and orthonormal (docs/shell.md §2.8.1–2.8.2).
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

/// t1 from the coordinate axis least aligned with d (Gram-Schmidt), t2 = d x t1.
void tangent_basis(const Vec3& d, Vec3& t1, Vec3& t2);

/// Area-weighted average of the facet normals at each node (unit vectors).
Points area_weighted_normals(const Points& X, const Triangles& tri);

}  // namespace capsflow::shell
