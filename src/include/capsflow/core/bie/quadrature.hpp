#pragma once
// Quadrature rules on P1 triangles — flat facets or their quadratic lift (curved_triangle.hpp) —
// for the single-layer Stokeslet and the double-layer stresslet (docs/boundary-integral.md).
// Conventions: fmm::Stokeslet, G(r) = I/|r| + r rᵀ/|r|³ with r = x − y; the scale 1/(8πμ) is NOT
// included here (the caller applies fmm::Stokeslet::scale()).
#include <array>
#include <vector>

#include "capsflow/core/bie/curved_triangle.hpp"
#include "capsflow/core/bie/stokeslet_batch.hpp"
#include "capsflow/core/types.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow {

// Gauss–Legendre rule on [0, 1] with n points (nodes by Newton iteration on P_n; exact for
// polynomials of degree 2n − 1).
struct GaussLegendre {
  std::vector<double> x, w;
  explicit GaussLegendre(int n);
};

// The 3-point interior rule (barycentrics (2/3, 1/6, 1/6) and permutations, weights A/3; exact
// for degree 2). kGaussBary[g][k] = λ_k at Gauss point g. The single layer's band rule.
inline constexpr double kGaussBary[3][3] = {{2.0 / 3, 1.0 / 6, 1.0 / 6}, {1.0 / 6, 2.0 / 3, 1.0 / 6}, {1.0 / 6, 1.0 / 6, 2.0 / 3}};

// The edge-midpoint rule (weights A/3; exact for degree 2, its cubic error 9× the 3-point rule's):
// kEdgeMidpointBary[k] = λ at the midpoint of edge (k, k+1). Its points lie on the edges, so the
// two elements of an edge share one point: the far-field sources (one per edge).
inline constexpr double kEdgeMidpointBary[3][3] = {{0.5, 0.5, 0.0}, {0.0, 0.5, 0.5}, {0.5, 0.0, 0.5}};

// Dunavant's 7-point rule (degree 5) on a triangle: barycentrics λ0..λ2 and weight (sum 1).
extern const double kDunavant7[7][4];

// The 4-to-1 midpoint split of a sub-triangle given by its vertices' parent barycentrics (rows).
std::array<Eigen::Matrix3d, 4> split_in_four(const Eigen::Matrix3d& bary);

// ∫_e G(x0 − y) φ_k(y) dS_y (k = 0, 1, 2) over a quadratic triangle written about its vertex x0,
// the (singular) target. The flat facet (x0, x1, x2) is integrated in closed form (exact); for a
// curved triangle the difference curved − flat is added by Duffy quadrature: with
// (ξ, η) = (u(1 − v), uv), y − x0 = u w(u, v), w = a1(v) + u a2(v), the Jacobian u cancels
// 1/|x0 − y| and G dS = G(w) J(u, v) du dv is smooth (docs/boundary-integral.md §4.1.2). `rule_v` integrates v on
// each side of the foot v* of the perpendicular from x0 on the opposite edge, after
// v = v* ± (d/|x2 − x1|) sinh s (flattens the peak of 1/|e(v)| at obtuse angles); `rule_u`
// integrates u. The difference is O(h/R) of the whole and smooth, so small rules suffice.
std::array<Mat3, 3> singular_element_integral(const QuadraticTriangle& T, const GaussLegendre& rule_v,
                                              const GaussLegendre& rule_u);
// Flat-facet form (closed form, no quadrature): the triangle (x0, x1, x2) with x0 the target.
std::array<Mat3, 3> singular_element_integral(const Vec3& x0, const Vec3& x1, const Vec3& x2);

// The double layer of a singular element (docs/boundary-integral.md §4.7.2): the matrices
// M_k = ∫_e T(x0 − y)·n(y) φ_k(y) dS_y, (M_k)_ij = ∫ T_ijl n_l φ_k dS, with T_ijl(r) = −6 r_i r_j r_l/|r|⁵
// (unscaled), over a quadratic triangle written about its vertex x0. Zero on a flat facet (r lies
// in its plane); on a curved element T(x0 − y)·n dS is O(1/|r|) and the same Duffy points as
// above integrate it (with n dS = ∂y/∂ξ × ∂y/∂η dξ dη, no flat part to subtract).
std::array<Mat3, 3> singular_element_double_layer(const QuadraticTriangle& T, const GaussLegendre& rule_v,
                                                  const GaussLegendre& rule_u);

// ∫_e G(p − y) φ_k(y) dS_y (k = 0, 1, 2) for a target p off the element (near-singular but not
// singular): the element is split 4^depth times in (ξ, η) and Dunavant's degree-5 7-point rule
// is applied on each part.
std::array<Mat3, 3> refined_element_integral(const Vec3& p, const QuadraticTriangle& T, int depth);
std::array<Mat3, 3> refined_element_integral(const Vec3& p, const Vec3& x0, const Vec3& x1, const Vec3& x2, int depth);

// ∫_e G(p − y) q(y) dS_y for a P1 load (q0, q1, q2 at T's vertices x0, x1, x2) and a target p near
// the element but not on it (another surface, a point of the flow): the element is split 4-to-1
// until each part lies farther than kAdaptiveSplitRatio of its diameters from p, at most
// kAdaptiveMaxDepth times, with Dunavant's 7 points on each part. A target on the element gets 0
// (no finite quadrature: its callers report such targets as too close).
inline constexpr double kAdaptiveSplitRatio = 4.0;
inline constexpr int kAdaptiveMaxDepth = 14;
Vec3 adaptive_element_apply(const Vec3& p, const QuadraticTriangle& T, const Vec3& q0, const Vec3& q1, const Vec3& q2);
// The double layer's counterpart: ∫_e T(p − y) : u(y) n(y) dS_y (T_ijk = −6 r_i r_j r_k/|r|⁵,
// unscaled, docs/boundary-integral.md §4.7.1) for a P1 velocity (u_k at x0, x1, x2), by the same
// subdivision: a fixed wall's prescribed velocity seen from a point of the flow.
Vec3 adaptive_element_double_layer(const Vec3& p, const QuadraticTriangle& T, const Vec3& u0, const Vec3& u1,
                                   const Vec3& u2);

// Hot-path forms, applied to a P1 load (q_k at the element's vertices, in the order x0, x1, x2 of
// T). Singular element: returns the closed-form flat part Σ_k (∫ G φ_k dS) q_k and pushes the
// curvature-correction points as Stokeslet terms (w, weight · q(y)) into `batch` (none when flat);
// the caller adds batch.sum(). Same points and weights as the matrix form.
Vec3 singular_element_apply(StokesletBatch& batch, const QuadraticTriangle& T, const Vec3& q0, const Vec3& q1,
                            const Vec3& q2, const GaussLegendre& rule_v, const GaussLegendre& rule_u);

// G(r) applied to f, and G(r) as a matrix: fmm::Stokeslet's pair formula (unscaled).
inline Vec3 stokeslet_apply(const Vec3& r, const Vec3& f) {
  double u[3] = {0, 0, 0};
  const double rr[3] = {r.x(), r.y(), r.z()}, ff[3] = {f.x(), f.y(), f.z()};
  fmm::Stokeslet::eval(u, rr, fmm::simd::rsqrt(r.squaredNorm()), ff);
  return {u[0], u[1], u[2]};
}
inline Mat3 stokeslet_matrix(const Vec3& r) {
  Mat3 G;
  for (int k = 0; k < 3; ++k) G.col(k) = stokeslet_apply(r, Vec3::Unit(k));
  return G;
}

}  // namespace capsflow
