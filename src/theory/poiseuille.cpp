#include "capsflow/core/theory/poiseuille.hpp"

#include <algorithm>
#include <cmath>

namespace capsflow {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxN = 2000001;  // the largest odd n; reached only within ~1e-5 W of a corner

// cosh(a t)/cosh(a) for 0 ≤ t ≤ 1, without overflow.
double cosh_ratio(double a, double t) { return std::exp(a * (t - 1)) * (1 + std::exp(-2 * a * t)) / (1 + std::exp(-2 * a)); }

// G W² for the mean velocity V.
double duct_g_w2(double V) {
  double s = 0;
  for (int n = 1; n < 400; n += 2) s += std::tanh(n * kPi / 2) / std::pow(n, 5);
  return 3 * V / (1 - 192 / std::pow(kPi, 5) * s);
}

// Σ_{n odd} c_n(n) cosh(a_n t)/cosh(a_n) until the cosh ratio is below 1e-17 (terms bounded by it).
template <class Coefficient>
double exponential_series(double t, const Coefficient& c) {
  double sum = 0;
  for (int n = 1; n <= kMaxN; n += 2) {
    const double ratio = cosh_ratio(n * kPi / 2, t);
    sum += c(n) * ratio;
    if (ratio < 1e-17) break;
  }
  return sum;
}

}  // namespace

double tube_poiseuille_velocity(double r, double R, double V) { return 2 * V * (1 - (r * r) / (R * R)); }
double tube_poiseuille_pressure_gradient(double R, double V) { return -8 * V / (R * R); }
double tube_poiseuille_wall_shear(double R, double V) { return 4 * V / R; }

double duct_poiseuille_velocity(double y, double z, double W, double V) {
  double s = std::abs(y) / W, t = std::abs(z) / W;
  if (t > s) std::swap(s, t);  // the cosh in the smaller coordinate
  if (s >= 1) return 0;
  const double series = exponential_series(t, [s](int n) {
    const double sign = ((n - 1) / 2) % 2 == 0 ? 1.0 : -1.0;
    return sign * std::cos(n * kPi / 2 * s) / (static_cast<double>(n) * n * n);
  });
  return duct_g_w2(V) * (0.5 * (1 - s * s) - 16 / (kPi * kPi * kPi) * series);
}

double duct_poiseuille_pressure_gradient(double W, double V) { return -duct_g_w2(V) / (W * W); }

double duct_poiseuille_wall_shear(double y, double W, double V) {
  const double s = std::min(1.0, std::abs(y) / W);
  const double series = exponential_series(s, [](int n) { return 1 / (static_cast<double>(n) * n); });
  return duct_g_w2(V) / W * (1 - 8 / (kPi * kPi) * series);
}

}  // namespace capsflow
