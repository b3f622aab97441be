#include "capsflow/core/bie/quadrature.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "capsflow/core/bie/point_triangle.hpp"

namespace capsflow {

GaussLegendre::GaussLegendre(int n) : x(static_cast<size_t>(n)), w(static_cast<size_t>(n)) {
  if (n < 1) throw std::invalid_argument("Gauss–Legendre rule needs n >= 1");
  for (int i = 0; i < n; ++i) {
    double t = std::cos(M_PI * (i + 0.75) / (n + 0.5));  // Tricomi initial guess on [−1, 1]
    double dp = 1;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = t;  // P_0, P_1; recurrence to P_n
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * t * p1 - (k - 1) * p0) / k;
        p0 = p1, p1 = p2;
      }
      if (n == 1) p0 = 1;
      dp = n * (t * p1 - p0) / (t * t - 1);
      const double dt = p1 / dp;
      t -= dt;
      if (std::abs(dt) < 1e-16) break;
    }
    // map [−1, 1] -> [0, 1]
    x[static_cast<size_t>(i)] = 0.5 * (1 - t);
    w[static_cast<size_t>(i)] = 1.0 / ((1 - t * t) * dp * dp);
  }
}

namespace {

// Closed form of the flat singular element (docs/boundary-integral.md §4.1.1): with e(v) = F1 + v(F2 − F1),
//   K0 = ∫_0^1 (I/|e| + e eᵀ/|e|³) dv,   K1 = ∫_0^1 v (I/|e| + e eᵀ/|e|³) dv,
// so that ∫_e G φ_k dS = A·(K0, K0 − K1, K1)_k. Along the edge line, e = d n̂ + t b̂ with d the
// distance from x0 to the line and t the arclength from the foot; every primitive is then
// elementary (asinh(t/d), r = √(d² + t²), t/r, d/r) and free of cancellation for sane shapes.
void flat_singular(const Vec3& F1, const Vec3& F2, Mat3& K0, Mat3& K1) {
  const Vec3 b = F2 - F1;
  const double blen = b.norm();
  const Vec3 bh = b / blen;
  const double ta = F1.dot(bh), tb = ta + blen;  // t at v = 0 and v = 1
  const Vec3 foot = F1 - ta * bh;
  const double d = foot.norm();
  const Vec3 nh = foot / d;
  const double ra = std::hypot(d, ta), rb = std::hypot(d, tb);
  const double P0 = std::asinh(tb / d) - std::asinh(ta / d);  // ∫ dt/r
  const double P1 = rb - ra;                                 // ∫ t dt/r
  const double Tnn = tb / rb - ta / ra;                      // ∫ d²/r³ dt
  const double Tnb = d / ra - d / rb;                        // ∫ d t/r³ dt
  const double Tbb = P0 - Tnn;                               // ∫ t²/r³ dt
  const double Mnn = d * d / ra - d * d / rb;                // ∫ t d²/r³ dt
  const double Mnb = d * Tbb;                                // ∫ t · d t/r³ dt
  const double Mbb = (rb + d * d / rb) - (ra + d * d / ra);  // ∫ t³/r³ dt
  const Mat3 Nn = nh * nh.transpose(), Nb = nh * bh.transpose() + bh * nh.transpose(), Bb = bh * bh.transpose();
  K0 = (P0 * Mat3::Identity() + Tnn * Nn + Tnb * Nb + Tbb * Bb) / blen;
  // v = (t − ta)/|b|, dv = dt/|b|
  K1 = ((P1 - ta * P0) * Mat3::Identity() + (Mnn - ta * Tnn) * Nn + (Mnb - ta * Tnb) * Nb + (Mbb - ta * Tbb) * Bb) /
       (blen * blen);
}

// The Duffy lines of a singular element written about its vertex x0 (docs/boundary-integral.md
// §4.1.2): calls f(v, wv) for the points of `rule_v` on each side of the foot v* of the
// perpendicular from x0 to the opposite edge, after v = v* ± (d/|x2 − x1|) sinh s (flattens the
// peak of 1/|e(v)| at obtuse angles); wv includes the substitution's Jacobian.
template <class F>
void visit_duffy_lines(const QuadraticTriangle& T, const GaussLegendre& rule_v, F&& f) {
  const Vec3& a = T.F1;
  const Vec3 b = T.F2 - T.F1;
  const double bb = b.squaredNorm(), blen = std::sqrt(bb);
  const double vstar = std::clamp(-a.dot(b) / bb, 0.0, 1.0);
  const double d = (a + vstar * b).norm();
  for (const double sign : {1.0, -1.0}) {
    const double length = sign > 0 ? 1.0 - vstar : vstar;
    if (length <= 0) continue;
    const double smax = std::asinh(blen * length / d);
    for (size_t k = 0; k < rule_v.x.size(); ++k) {
      const double ex = std::exp(rule_v.x[k] * smax), inv = 1.0 / ex;  // one exp for sinh and cosh
      f(vstar + sign * (d / blen) * 0.5 * (ex - inv), rule_v.w[k] * smax * (d / blen) * 0.5 * (ex + inv));
    }
  }
}

// The curvature correction of a singular element: calls f(w, weight, λ) for the Duffy points of
// the quadratic triangle and, with the opposite weight, for those of its flat facet at the same
// v; a point contributes weight · G(w) · φ(λ). See singular_element_integral in the header.
constexpr size_t kMaxRadialPoints = 16;

template <class F>
void visit_curvature_correction(const QuadraticTriangle& T, const GaussLegendre& rule_v, const GaussLegendre& rule_u,
                                F&& f) {
  const Vec3 b = T.F2 - T.F1, bc = T.B - T.A;
  const size_t nu = rule_u.x.size();
  if (nu > kMaxRadialPoints) throw std::invalid_argument("curvature correction: at most 16 Gauss points in u");
  visit_duffy_lines(T, rule_v, [&](double v, double wv) {
    const Vec3 a1 = T.A + v * bc, a1_flat = T.F1 + v * b;
    const Vec3 a2 = (1 - v) * (1 - v) * T.C + v * v * T.D + v * (1 - v) * T.E;
    // Jacobians of all u-points first: independent square roots pipeline instead of stalling
    // each point (the loop is latency-bound otherwise).
    double jac[kMaxRadialPoints];
    for (size_t m = 0; m < nu; ++m) jac[m] = T.jacobian_squared(rule_u.x[m] * (1 - v), rule_u.x[m] * v);
    for (size_t m = 0; m < nu; ++m) jac[m] = std::sqrt(jac[m]);
    for (size_t m = 0; m < nu; ++m) {
      const double u = rule_u.x[m];
      f(a1 + u * a2, wv * rule_u.w[m] * jac[m], Vec3(1 - u, u * (1 - v), u * v));
    }
    // The flat integrand G(a1_flat) J0 φ(λ) is linear in u: its u-integral is the value at u = ½.
    f(a1_flat, -wv * T.J0, Vec3(0.5, 0.5 * (1 - v), 0.5 * v));
  });
}

}  // namespace

std::array<Mat3, 3> singular_element_integral(const QuadraticTriangle& T, const GaussLegendre& rule_v,
                                              const GaussLegendre& rule_u) {
  Mat3 K0, K1;
  flat_singular(T.F1, T.F2, K0, K1);
  const double area = 0.5 * T.J0;
  std::array<Mat3, 3> out{area * K0, area * (K0 - K1), area * K1};
  if (T.curved)
    visit_curvature_correction(T, rule_v, rule_u, [&](const Vec3& w, double weight, const Vec3& lam) {
      const Mat3 g = weight * stokeslet_matrix(w);
      for (int k = 0; k < 3; ++k) out[k] += lam[k] * g;
    });
  return out;
}

std::array<Mat3, 3> singular_element_integral(const Vec3& x0, const Vec3& x1, const Vec3& x2) {
  const GaussLegendre unused(1);
  return singular_element_integral(QuadraticTriangle::flat(x0, x1, x2), unused, unused);
}

Vec3 singular_element_apply(StokesletBatch& batch, const QuadraticTriangle& T, const Vec3& q0, const Vec3& q1,
                            const Vec3& q2, const GaussLegendre& rule_v, const GaussLegendre& rule_u) {
  Mat3 K0, K1;
  flat_singular(T.F1, T.F2, K0, K1);
  if (T.curved)
    visit_curvature_correction(T, rule_v, rule_u, [&](const Vec3& w, double weight, const Vec3& lam) {
      batch.push(w, weight * (lam[0] * q0 + lam[1] * q1 + lam[2] * q2));
    });
  return (0.5 * T.J0) * (K0 * (q0 + q1) + K1 * (q2 - q1));
}

std::array<Mat3, 3> singular_element_double_layer(const QuadraticTriangle& T, const GaussLegendre& rule_v,
                                                  const GaussLegendre& rule_u) {
  std::array<Mat3, 3> out{Mat3::Zero(), Mat3::Zero(), Mat3::Zero()};
  if (!T.curved) return out;  // r = x0 − y lies in the facet's plane: T(r)·n = 0 on the whole facet
  const Vec3 bc = T.B - T.A;
  visit_duffy_lines(T, rule_v, [&](double v, double wv) {
    const Vec3 a1 = T.A + v * bc;
    const Vec3 a2 = (1 - v) * (1 - v) * T.C + v * v * T.D + v * (1 - v) * T.E;
    for (size_t m = 0; m < rule_u.x.size(); ++m) {
      const double u = rule_u.x[m];
      const Vec3 w = a1 + u * a2, N = T.area_normal(u * (1 - v), u * v);
      // T(−u w)·N u = 6 (w·N) w wᵀ/(u |w|⁵): w·N = O(u) because a1 lies in the tangent plane at x0.
      const double winv = 1.0 / w.norm(), winv2 = winv * winv;
      const Mat3 K = (6.0 * wv * rule_u.w[m] * w.dot(N) / u * winv2 * winv2 * winv) * (w * w.transpose());
      out[0] += (1 - u) * K, out[1] += (u * (1 - v)) * K, out[2] += (u * v) * K;
    }
  });
  return out;
}

namespace {
constexpr double kA1 = 0.059715871789770, kB1 = 0.470142064105115, kW1 = 0.132394152788506;
constexpr double kA2 = 0.797426985353087, kB2 = 0.101286507323456, kW2 = 0.125939180544827;
}  // namespace

const double kDunavant7[7][4] = {{1.0 / 3, 1.0 / 3, 1.0 / 3, 0.225},
                                 {kA1, kB1, kB1, kW1}, {kB1, kA1, kB1, kW1}, {kB1, kB1, kA1, kW1},
                                 {kA2, kB2, kB2, kW2}, {kB2, kA2, kB2, kW2}, {kB2, kB2, kA2, kW2}};

std::array<Eigen::Matrix3d, 4> split_in_four(const Eigen::Matrix3d& bary) {
  const Eigen::RowVector3d m01 = 0.5 * (bary.row(0) + bary.row(1)), m12 = 0.5 * (bary.row(1) + bary.row(2)),
                           m20 = 0.5 * (bary.row(2) + bary.row(0));
  std::array<Eigen::Matrix3d, 4> c;
  c[0] << bary.row(0), m01, m20;
  c[1] << m01, bary.row(1), m12;
  c[2] << m20, m12, bary.row(2);
  c[3] << m01, m12, m20;
  return c;
}


namespace {
// bary: the sub-triangle's vertices in parent barycentrics (rows); param_area: its area in (ξ, η).
void refine(const Vec3& p, const QuadraticTriangle& T, const Eigen::Matrix3d& bary, double param_area, int depth,
            std::array<Mat3, 3>& out) {
  if (depth == 0) {
    for (const auto& r : kDunavant7) {
      const Eigen::RowVector3d lam = r[0] * bary.row(0) + r[1] * bary.row(1) + r[2] * bary.row(2);
      const Mat3 g = (r[3] * param_area * T.jacobian(lam[1], lam[2])) * stokeslet_matrix(p - T.position(lam[1], lam[2]));
      for (int k = 0; k < 3; ++k) out[k] += lam[k] * g;
    }
    return;
  }
  const std::array<Eigen::Matrix3d, 4> c = split_in_four(bary);
  for (const auto& sub : c) refine(p, T, sub, param_area / 4, depth - 1, out);
}
}  // namespace

std::array<Mat3, 3> refined_element_integral(const Vec3& p, const QuadraticTriangle& T, int depth) {
  std::array<Mat3, 3> out{Mat3::Zero(), Mat3::Zero(), Mat3::Zero()};
  refine(p, T, Eigen::Matrix3d::Identity(), 0.5, depth, out);
  return out;
}

std::array<Mat3, 3> refined_element_integral(const Vec3& p, const Vec3& x0, const Vec3& x1, const Vec3& x2, int depth) {
  return refined_element_integral(p, QuadraticTriangle::flat(x0, x1, x2), depth);
}

namespace {
// The part of T with parent barycentrics `bary` (rows; area param_area in (ξ, η)), split until it
// lies farther than kAdaptiveSplitRatio of its diameters from p; distances from its corners. At
// each of Dunavant's points `term(λ, y, w)` gives the kernel's contribution, w the point's weight
// in (ξ, η) (without the area element: each kernel takes J or the area normal itself).
template <class Term>
Vec3 adaptive_part(const Vec3& p, const QuadraticTriangle& T, const Term& term, const Eigen::Matrix3d& bary,
                   double param_area, int depth) {
  Vec3 y[3];
  for (int v = 0; v < 3; ++v) y[v] = T.position(bary(v, 1), bary(v, 2));
  const double diam = std::max({(y[1] - y[0]).norm(), (y[2] - y[1]).norm(), (y[0] - y[2]).norm()});
  const double dist = point_triangle_distance(p, y[0], y[1], y[2]);
  if (dist > kAdaptiveSplitRatio * diam || depth >= kAdaptiveMaxDepth) {
    Vec3 sum = Vec3::Zero();
    if (dist <= 0) return sum;
    for (const auto& r : kDunavant7) {
      const Eigen::RowVector3d lam = r[0] * bary.row(0) + r[1] * bary.row(1) + r[2] * bary.row(2);
      sum += term(lam, T.position(lam[1], lam[2]), r[3] * param_area);
    }
    return sum;
  }
  const std::array<Eigen::Matrix3d, 4> c = split_in_four(bary);
  Vec3 sum = Vec3::Zero();
  for (const auto& sub : c) sum += adaptive_part(p, T, term, sub, param_area / 4, depth + 1);
  return sum;
}
}  // namespace

Vec3 adaptive_element_apply(const Vec3& p, const QuadraticTriangle& T, const Vec3& q0, const Vec3& q1, const Vec3& q2) {
  auto term = [&](const Eigen::RowVector3d& lam, const Vec3& y, double w) -> Vec3 {
    const Vec3 q = lam[0] * q0 + lam[1] * q1 + lam[2] * q2;
    return (w * T.jacobian(lam[1], lam[2])) * stokeslet_apply(p - y, q);
  };
  return adaptive_part(p, T, term, Eigen::Matrix3d::Identity(), 0.5, 0);
}

Vec3 adaptive_element_double_layer(const Vec3& p, const QuadraticTriangle& T, const Vec3& u0, const Vec3& u1,
                                   const Vec3& u2) {
  auto term = [&](const Eigen::RowVector3d& lam, const Vec3& y, double w) -> Vec3 {
    const Vec3 u = lam[0] * u0 + lam[1] * u1 + lam[2] * u2;
    const Vec3 r = p - y, N = T.area_normal(lam[1], lam[2]);  // N = n J
    const double r2 = r.squaredNorm();
    return (w * -6 * r.dot(u) * r.dot(N) / (r2 * r2 * std::sqrt(r2))) * r;
  };
  return adaptive_part(p, T, term, Eigen::Matrix3d::Identity(), 0.5, 0);
}

}  // namespace capsflow
