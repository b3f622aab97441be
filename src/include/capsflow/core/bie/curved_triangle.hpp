#pragma once
// Curved (quadratic) triangles reconstructed from a P1 mesh and its vertex normals, for the
// boundary-integral quadrature (fluid.geometry = "curved").
//
// A flat facet misplaces the surface by O(h²) and limits the single layer to O(h²) with a large
// constant (docs/boundary-integral.md §4.4). Each edge (a, b) is lifted to the midpoint of the cubic Hermite
// curve whose end tangents lie in the tangent planes of a and b:
//     m_ab = (x_a + x_b)/2 + [(e·n_b) n_b − (e·n_a) n_a]/8,   e = x_b − x_a,
// which is symmetric in (a, b), so the two elements sharing an edge agree (a watertight surface),
// and lies on the sphere to O(h⁴) when the normals are exact. The element is then the 6-node
// quadratic triangle through the vertices and the three lifted midpoints; with m_ab = (x_a+x_b)/2
// it is the flat facet exactly, so one code path serves both geometries.
#include <cmath>

#include "capsflow/core/types.hpp"

namespace capsflow {

// Vertex normals with Max's (1999) weights, n_i ∝ Σ_faces (e1 × e2)/(|e1|²|e2|²): exact for
// vertices on a sphere, O(h²) on smooth surfaces for any triangulation.
// Written into n (storage reused when n already has the size).
void vertex_normals_max(const Points& x, const Triangles& t, Points& n);

// The lifted midpoint of edge (a, b) described above.
inline Vec3 hermite_edge_midpoint(const Vec3& xa, const Vec3& xb, const Vec3& na, const Vec3& nb) {
  const Vec3 e = xb - xa;
  return 0.5 * (xa + xb) + 0.125 * (e.dot(nb) * nb - e.dot(na) * na);
}

// The quadratic triangle written about one of its vertices x0, in the coordinates (ξ, η) = (λ1, λ2):
//     y(ξ, η) = x0 + ξ A + η B + ξ² C + η² D + ξη E.
// From the 6-node form y = Σ λk(2λk−1) xk + 4(λ0λ1 m01 + λ1λ2 m12 + λ2λ0 m20).
struct QuadraticTriangle {
  Vec3 x0, A, B, C, D, E;
  Vec3 F1, F2;        // flat-facet edges x1 − x0, x2 − x0
  double J0;          // flat-facet Jacobian |F1 × F2| (= 2·area)
  bool curved = true; // false: C = D = E = 0 and J ≡ J0 (skips the per-point cross product)

  // Vertices x0, x1, x2 (counter-clockwise) and midpoints m01, m12, m20.
  QuadraticTriangle(const Vec3& x0_, const Vec3& x1, const Vec3& x2, const Vec3& m01, const Vec3& m12, const Vec3& m20)
      : x0(x0_),
        A(4 * m01 - 3 * x0_ - x1),
        B(4 * m20 - 3 * x0_ - x2),
        C(2 * (x0_ + x1) - 4 * m01),
        D(2 * (x0_ + x2) - 4 * m20),
        E(4 * (x0_ + m12 - m01 - m20)),
        F1(x1 - x0_),
        F2(x2 - x0_),
        J0(F1.cross(F2).norm()) {}
  // The flat facet (x0, x1, x2).
  static QuadraticTriangle flat(const Vec3& x0, const Vec3& x1, const Vec3& x2) {
    QuadraticTriangle t(x0, x1, x2, 0.5 * (x0 + x1), 0.5 * (x1 + x2), 0.5 * (x2 + x0));
    t.A = t.F1, t.B = t.F2;
    t.C.setZero(), t.D.setZero(), t.E.setZero();
    t.curved = false;
    return t;
  }

  // y − x0 (no cancellation near x0).
  Vec3 offset(double xi, double eta) const { return xi * (A + xi * C + eta * E) + eta * (B + eta * D); }
  Vec3 position(double xi, double eta) const { return x0 + offset(xi, eta); }
  // |∂y/∂ξ × ∂y/∂η|: the area element, dS = J dξ dη (J = 2·area for a flat facet).
  double jacobian(double xi, double eta) const { return curved ? std::sqrt(jacobian_squared(xi, eta)) : J0; }
  double jacobian_squared(double xi, double eta) const { return area_normal(xi, eta).squaredNorm(); }
  // ∂y/∂ξ × ∂y/∂η: the outward normal times the area element J (counter-clockwise vertices).
  Vec3 area_normal(double xi, double eta) const {
    const Vec3 dxi = A + 2 * xi * C + eta * E, deta = B + 2 * eta * D + xi * E;
    return dxi.cross(deta);
  }
};

// Element e of the surface (x, t) as its flat facet.
inline QuadraticTriangle flat_element(const Points& x, const Triangles& t, Eigen::Index e) {
  return QuadraticTriangle::flat(x.row(t(e, 0)).transpose(), x.row(t(e, 1)).transpose(), x.row(t(e, 2)).transpose());
}

}  // namespace capsflow
