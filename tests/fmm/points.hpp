#pragma once
// Test point distributions (sphere surface, spheroid a/b = 1.4 surface, uniform cube, clustered),
// densities (random; a smooth or a random double layer on the sphere or spheroid) and error metrics shared by
// the fmm tests and perf/fmm.
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace capsflow::fmm::testing {

inline std::vector<double> make_points(const std::string& dist, std::size_t n, unsigned seed) {
  std::mt19937_64 g(seed);
  std::normal_distribution<double> nd;
  std::uniform_real_distribution<double> ud(-1, 1);
  std::vector<double> p(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    double x[3];
    if (dist == "sphere" || dist == "spheroid") {
      double r2 = 0;
      for (double& v : x) { v = nd(g); r2 += v * v; }
      for (double& v : x) v /= std::sqrt(r2);
      if (dist == "spheroid") {  // X1²/b² + X2²/b² + X3²/a² = 1, a/b = 1.4, a b² = 1
        const double b = std::cbrt(1.0 / 1.4), a = 1.4 * b;
        x[0] *= b; x[1] *= b; x[2] *= a;
      }
    } else if (dist == "cube") {
      for (double& v : x) v = ud(g);
    } else {  // clustered: Gaussian blobs of very different widths
      const int c = static_cast<int>(i % 4);
      const double w[4] = {0.3, 0.05, 0.01, 0.002};
      const double ctr[4][3] = {{0, 0, 0}, {0.7, 0.2, -0.4}, {-0.5, 0.6, 0.5}, {0.3, -0.8, 0.1}};
      for (int d = 0; d < 3; ++d) x[d] = ctr[c][d] + w[c] * nd(g);
    }
    for (int d = 0; d < 3; ++d) p[3 * i + d] = x[d];
  }
  return p;
}

inline std::vector<double> random_density(std::size_t n, unsigned seed) {
  std::mt19937_64 g(seed);
  std::normal_distribution<double> nd;
  std::vector<double> f(n);
  for (auto& v : f) v = nd(g);
  return f;
}

/// The density of a surface double layer on the points of make_points("sphere" or "spheroid"):
/// per point f = w·u(y) and n = the outward unit normal (stresslet.hpp's 6 components), with
/// w = area/N (the equal-area weight on the sphere; of the right size on the spheroid, whose
/// points are not uniform) and a smooth velocity u = (y0·y1, sin 2y2, y0 − y2²). The
/// boundary integral's use of the stresslet: the sum carries the cancellations of a closed surface
/// (for constant u it is u inside, 0 outside), unlike random densities.
inline std::vector<double> surface_double_layer(const std::string& dist, const std::vector<double>& p) {
  const std::size_t n = p.size() / 3;
  const bool spheroid = dist == "spheroid";
  const double b = std::cbrt(1.0 / 1.4), a = 1.4 * b;
  // area of the sphere, or of the prolate spheroid (semi-axes b, b, a; e = eccentricity)
  const double e = std::sqrt(1 - b * b / (a * a));
  const double pi = 3.14159265358979323846;
  const double area = spheroid ? 2 * pi * b * b * (1 + a / (b * e) * std::asin(e)) : 4 * pi;
  std::vector<double> d(6 * n);
  for (std::size_t j = 0; j < n; ++j) {
    const double* y = &p[3 * j];
    double nv[3] = {y[0], y[1], y[2]};
    if (spheroid) { nv[0] /= b * b; nv[1] /= b * b; nv[2] /= a * a; }
    const double len = std::sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
    const double u[3] = {y[0] * y[1], std::sin(2 * y[2]), y[0] - y[2] * y[2]};
    for (int k = 0; k < 3; ++k) {
      d[6 * j + k] = area / static_cast<double>(n) * u[k];
      d[6 * j + 3 + k] = nv[k] / len;
    }
  }
  return d;
}

/// Random f (normal components, seed) with n the outward unit normal at the points of
/// make_points("sphere" or "spheroid"): the stresslet's 6 components per point. A rough density on a
/// closed surface: the outward normals make the sum cancel as the smooth double layer's does (a
/// constant f gives f inside, 0 outside), but its result is the sum of uncorrelated terms of every
/// size, so its relative error is larger than random f with random n at the same order (the case
/// the stresslet's calibration missed at 1e-6 with small leaves, calibration.hpp).
inline std::vector<double> random_surface_double_layer(const std::string& dist, const std::vector<double>& p,
                                                       unsigned seed) {
  std::vector<double> d = surface_double_layer(dist, p);
  const std::vector<double> f = random_density(3 * (p.size() / 3), seed);
  for (std::size_t j = 0; j < p.size() / 3; ++j)
    for (int k = 0; k < 3; ++k) d[6 * j + k] = f[3 * j + k];
  return d;
}

inline double rel_l2(const std::vector<double>& a, const std::vector<double>& ref) {
  double num = 0, den = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    num += (a[i] - ref[i]) * (a[i] - ref[i]);
    den += ref[i] * ref[i];
  }
  return den > 0 ? std::sqrt(num / den) : std::sqrt(num);
}

}  // namespace capsflow::fmm::testing
