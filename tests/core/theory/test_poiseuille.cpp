// The Poiseuille flows of theory/poiseuille.hpp against what defines them: the Stokes equation
// Δu = dp/dx (finite differences), no slip on the walls, the mean velocity (quadrature), the force
// balance of the wall shear stress, and the square duct's published centreline ratio.
#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/bie/quadrature.hpp"
#include "capsflow/core/theory/poiseuille.hpp"

namespace capsflow {
namespace {

// ∫∫ f over [−W, W]² by Gauss–Legendre (n points per direction).
template <class F>
double square_integral(double W, int n, const F& f) {
  const GaussLegendre g(n);
  double s = 0;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < n; ++k) s += g.w[i] * g.w[k] * f(-W + 2 * W * g.x[i], -W + 2 * W * g.x[k]);
  return s * 4 * W * W;
}

TEST(Poiseuille, TubeMeanVelocityPressureGradientAndWallShear) {
  const double R = 1.3, V = 0.7;
  // Mean over the disc by the radial Gauss rule (exact for the quadratic profile): V to 1e-14.
  const GaussLegendre g(4);
  double mean = 0;
  for (std::size_t i = 0; i < g.x.size(); ++i) mean += g.w[i] * 2 * g.x[i] * tube_poiseuille_velocity(R * g.x[i], R, V);
  EXPECT_NEAR(mean, V, 1e-14);
  // (1/r) d/dr (r du/dr) = dp/dx, and −du/dr at the wall = 4V/R, by central differences (step 1e-4: error ~1e-8).
  const double h = 1e-4, r = 0.6;
  auto u = [&](double rr) { return tube_poiseuille_velocity(rr, R, V); };
  const double lap = (u(r + h) - 2 * u(r) + u(r - h)) / (h * h) + (u(r + h) - u(r - h)) / (2 * h * r);
  EXPECT_NEAR(lap, tube_poiseuille_pressure_gradient(R, V), 1e-6);
  EXPECT_NEAR(-(u(R) - u(R - h)) / h, tube_poiseuille_wall_shear(R, V), 1e-3);  // one-sided: O(h) = 2e-4
}

TEST(Poiseuille, DuctSatisfiesStokesNoSlipAndItsMeanVelocity) {
  const double W = 1.1, V = 0.8, G = -duct_poiseuille_pressure_gradient(W, V);
  auto u = [&](double y, double z) { return duct_poiseuille_velocity(y, z, W, V); };
  // Δu = −G at interior points (fourth-order differences, step 1e-3: truncation ~1e-11, round-off ~1e-9).
  const double h = 1e-3;
  for (const auto& p : {std::pair{0.0, 0.0}, {0.5, 0.2}, {-0.9, 0.7}, {0.3, -1.0}, {1.0, 1.0}}) {
    auto d2 = [&](double dy, double dz) {
      const double y = p.first, z = p.second;
      return (-u(y + 2 * dy, z + 2 * dz) + 16 * u(y + dy, z + dz) - 30 * u(y, z) + 16 * u(y - dy, z - dz) -
              u(y - 2 * dy, z - 2 * dz)) / (12 * h * h);
    };
    EXPECT_NEAR(d2(h, 0) + d2(0, h), -G, 1e-5 * G) << p.first << ", " << p.second;
  }
  // No slip: zero on every side (to the series' 1e-15).
  for (const double s : {-0.999, -0.5, 0.0, 0.3, 0.9}) {
    EXPECT_NEAR(u(W, s * W), 0, 1e-14);
    EXPECT_NEAR(u(s * W, -W), 0, 1e-14);
    EXPECT_NEAR(u(s * W, W * (1 - 1e-12)), 0, 1e-10);  // continuous up to the wall
  }
  // The mean velocity by 40 × 40 Gauss points (the field is smooth inside; error below 1e-10).
  EXPECT_NEAR(square_integral(W, 40, u) / (4 * W * W), V, 1e-10);
  // Centreline over mean: 2.0962 for the square (Shah & London, Laminar Flow Forced Convection in
  // Ducts, 1978, Table for rectangular ducts at aspect ratio 1: u_max/u_m = 2.0962; to its 5 digits).
  EXPECT_NEAR(u(0, 0) / V, 2.0962, 1e-4);
}

TEST(Poiseuille, DuctWallShearBalancesThePressureGradient) {
  const double W = 0.9, V = 1.0, G = -duct_poiseuille_pressure_gradient(W, V);
  // Force balance per unit length: perimeter 8W times the mean wall shear = G times the area 4W²,
  // so the mean over one side is G W/2 (Gauss rule along the side; the series is smooth there
  // except at the corners, where it vanishes like a power: 1e-6).
  const GaussLegendre g(60);
  double mean = 0;
  for (std::size_t i = 0; i < g.x.size(); ++i) mean += g.w[i] * duct_poiseuille_wall_shear(-W + 2 * W * g.x[i], W, V);
  EXPECT_NEAR(mean, G * W / 2, 1e-6 * G * W);
  // Against the velocity's one-sided difference at the wall (step 1e-5 W: O(h) error 1e-5).
  const double y = 0.37 * W, h = 1e-5 * W;
  const double slope = (duct_poiseuille_velocity(y, W - h, W, V) - duct_poiseuille_velocity(y, W, W, V)) / h;
  EXPECT_NEAR(slope, duct_poiseuille_wall_shear(y, W, V), 1e-4 * slope);
  // Zero at the corner (to the truncation of the series at n = 2·10⁶: 1e-6 of G W).
  EXPECT_NEAR(duct_poiseuille_wall_shear(W, W, V), 0, 1e-6 * G * W);
}

}  // namespace
}  // namespace capsflow
