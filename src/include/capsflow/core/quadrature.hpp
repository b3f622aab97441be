#pragma once
// Quadrature rules on flat P1 triangles for the single-layer Stokeslet (numerics.md §4).
// Conventions: G(r) = I/|r| + r rᵀ/|r|³ with r = x − y; the 1/(8πμ) factor is NOT included here.
#include <array>
#include <vector>

#include "capsflow/core/types.hpp"

namespace capsflow {

// Gauss–Legendre rule on [0, 1] with n points (nodes by Newton iteration on P_n; exact for
// polynomials of degree 2n − 1).
struct GaussLegendre {
  std::vector<double> x, w;
  explicit GaussLegendre(int n);
};

// The 3-point interior rule (barycentrics (2/3, 1/6, 1/6) and permutations, weights A/3; exact
// for degree 2). kGaussBary[g][k] = λ_k at Gauss point g. These points are the far-field sources.
inline constexpr double kGaussBary[3][3] = {{2.0 / 3, 1.0 / 6, 1.0 / 6}, {1.0 / 6, 2.0 / 3, 1.0 / 6}, {1.0 / 6, 1.0 / 6, 2.0 / 3}};

// Dunavant's 7-point rule (degree 5) on a triangle: barycentrics λ0..λ2 and weight (sum 1).
extern const double kDunavant7[7][4];

// The 4-to-1 midpoint split of a sub-triangle given by its vertices' parent barycentrics (rows).
std::array<Eigen::Matrix3d, 4> split_in_four(const Eigen::Matrix3d& bary);

// ∫_e G(x0 − y) φ_k(y) dS_y for k = 0, 1, 2 over the triangle (x0, x1, x2) whose vertex x0 is the
// (singular) target. Duffy map y = x0 + u e(v), e(v) = (x1 − x0) + v (x2 − x1): the Jacobian u
// cancels 1/|x0 − y| and the u-integral is analytic (numerics.md §4.1), leaving
// A ∫_0^1 w_k(v) (I + ê êᵀ)/|e(v)| dv with w = (1, 1 − v, v), integrated by `rule`.
std::array<Mat3, 3> singular_element_integral(const Vec3& x0, const Vec3& x1, const Vec3& x2, const GaussLegendre& rule);

// ∫_e G(p − y) φ_k(y) dS_y (k = 0, 1, 2) for a target p off the element (near-singular but not
// singular): the element is split 4^depth times and Dunavant's degree-5 7-point rule is applied
// on each part.
std::array<Mat3, 3> refined_element_integral(const Vec3& p, const Vec3& x0, const Vec3& x1, const Vec3& x2, int depth);

// Hot-path forms of the two integrals above, applied to a P1 load (q_k at the element's vertices,
// in the same order as the x_k): Σ_k (∫_e G φ_k dS) q_k, with vector algebra only.
Vec3 singular_element_apply(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& q0, const Vec3& q1, const Vec3& q2,
                            const GaussLegendre& rule);
Vec3 near_element_apply(const Vec3& p, const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& q0, const Vec3& q1,
                        const Vec3& q2);  // 7-point rule on the whole element (depth 0)

// G(r) applied to f: (f + r (r·f)/|r|²)/|r|.
inline Vec3 stokeslet_apply(const Vec3& r, const Vec3& f) {
  const double r2 = r.squaredNorm(), inv = 1.0 / std::sqrt(r2);
  return inv * (f + r * (r.dot(f) / r2));
}
inline Mat3 stokeslet_matrix(const Vec3& r) {
  const double r2 = r.squaredNorm(), inv = 1.0 / std::sqrt(r2);
  return inv * (Mat3::Identity() + r * r.transpose() / r2);
}

}  // namespace capsflow
