#include "capsflow/core/quadrature.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

std::array<Mat3, 3> singular_element_integral(const Vec3& x0, const Vec3& x1, const Vec3& x2, const GaussLegendre& rule) {
  const Vec3 a = x1 - x0, b = x2 - x1;
  const double area = 0.5 * a.cross(x2 - x0).norm();
  std::array<Mat3, 3> out{Mat3::Zero(), Mat3::Zero(), Mat3::Zero()};
  // |e(v)| is smallest at the foot v* of the perpendicular from x0 on the opposite edge; for an
  // obtuse angle at x0 the integrand 1/|e| is sharply peaked there. Split at v* and substitute
  // v = v* ± (d/|b|) sinh s, which turns 1/|e| dv into ds/|b| (smooth): accurate for any shape.
  const double bb = b.squaredNorm(), blen = std::sqrt(bb);
  const double vstar = std::clamp(-a.dot(b) / bb, 0.0, 1.0);
  const double d = (a + vstar * b).norm();
  auto accumulate = [&](double length, double sign) {
    if (length <= 0) return;
    const double smax = std::asinh(blen * length / d);
    for (size_t q = 0; q < rule.x.size(); ++q) {
      const double s = rule.x[q] * smax, sh = std::sinh(s);
      const double v = vstar + sign * (d / blen) * sh;
      const double jac = rule.w[q] * smax * (d / blen) * std::cosh(s);
      const Vec3 e = a + v * b;
      const double len = e.norm();
      const Vec3 eh = e / len;
      const Mat3 k = (jac * area / len) * (Mat3::Identity() + eh * eh.transpose());
      out[0] += k;
      out[1] += (1 - v) * k;
      out[2] += v * k;
    }
  };
  accumulate(1.0 - vstar, +1.0);
  accumulate(vstar, -1.0);
  return out;
}

Vec3 singular_element_apply(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& q0, const Vec3& q1, const Vec3& q2,
                            const GaussLegendre& rule) {
  // Same quadrature as singular_element_integral, contracted with the load first.
  const Vec3 a = x1 - x0, b = x2 - x1;
  const double area = 0.5 * a.cross(x2 - x0).norm();
  const double bb = b.squaredNorm(), blen = std::sqrt(bb);
  const double vstar = std::clamp(-a.dot(b) / bb, 0.0, 1.0);
  const double d = (a + vstar * b).norm();
  Vec3 sum = Vec3::Zero();
  for (const double sign : {1.0, -1.0}) {
    const double length = sign > 0 ? 1.0 - vstar : vstar;
    if (length <= 0) continue;
    const double smax = std::asinh(blen * length / d);
    for (size_t k = 0; k < rule.x.size(); ++k) {
      const double ex = std::exp(rule.x[k] * smax), inv = 1.0 / ex;  // one exp for sinh and cosh
      const double v = vstar + sign * (d / blen) * 0.5 * (ex - inv);
      const Vec3 e = a + v * b;
      const double len2 = e.squaredNorm();
      const Vec3 q = q0 + (1 - v) * q1 + v * q2;  // ∫ φ_k du weights (1, 1 − v, v)
      sum += (rule.w[k] * smax * (d / blen) * 0.5 * (ex + inv) / std::sqrt(len2)) * (q + e * (e.dot(q) / len2));
    }
  }
  return area * sum;
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
void refine(const Vec3& p, const Vec3 (&x)[3], const Eigen::Matrix3d& bary, double area, int depth, std::array<Mat3, 3>& out) {
  if (depth == 0) {
    for (const auto& r : kDunavant7) {
      const Eigen::RowVector3d lam = r[0] * bary.row(0) + r[1] * bary.row(1) + r[2] * bary.row(2);
      const Vec3 y = lam[0] * x[0] + lam[1] * x[1] + lam[2] * x[2];
      const Mat3 g = (r[3] * area) * stokeslet_matrix(p - y);
      for (int k = 0; k < 3; ++k) out[k] += lam[k] * g;
    }
    return;
  }
  const std::array<Eigen::Matrix3d, 4> c = split_in_four(bary);
  for (const auto& sub : c) refine(p, x, sub, area / 4, depth - 1, out);
}
}  // namespace

Vec3 near_element_apply(const Vec3& p, const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& q0, const Vec3& q1,
                        const Vec3& q2) {
  const double area = 0.5 * (x1 - x0).cross(x2 - x0).norm();
  Vec3 sum = Vec3::Zero();
  for (const auto& r : kDunavant7) {
    const Vec3 y = r[0] * x0 + r[1] * x1 + r[2] * x2;
    sum += r[3] * stokeslet_apply(p - y, r[0] * q0 + r[1] * q1 + r[2] * q2);
  }
  return area * sum;
}

std::array<Mat3, 3> refined_element_integral(const Vec3& p, const Vec3& x0, const Vec3& x1, const Vec3& x2, int depth) {
  const Vec3 x[3] = {x0, x1, x2};
  std::array<Mat3, 3> out{Mat3::Zero(), Mat3::Zero(), Mat3::Zero()};
  refine(p, x, Eigen::Matrix3d::Identity(), 0.5 * (x1 - x0).cross(x2 - x0).norm(), depth, out);
  return out;
}

}  // namespace capsflow
