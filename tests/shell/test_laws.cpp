// Membrane laws: tension vs finite differences of W, small-strain moduli, closed-form tensions.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "capsflow/shell/laws.hpp"

using namespace capsflow::shell;

namespace {
std::vector<MembraneLaw> all_laws() {
  return {make_law("gh", 1.3, 0.3, 0), make_law("nh", 0.7), make_law("skalak", 1.1, 0, 2.5),
          make_law("mr", 0.9, 0, 0.3)};
}
// W as a function of the symmetric membrane strain gamma (rr, ss, rs) for reference metric A
double W_of_gamma(const MembraneLaw& law, const double A[3], const double g[3]) {
  const double a[3] = {A[0] + 2 * g[0], A[1] + 2 * g[1], A[2] + 2 * g[2]};
  const double detA = A[0] * A[1] - A[2] * A[2];
  const double B[3] = {A[1] / detA, A[0] / detA, -A[2] / detA};
  const double I1 = B[0] * a[0] + B[1] * a[1] + 2 * B[2] * a[2] - 2;
  const double I2 = (a[0] * a[1] - a[2] * a[2]) / detA - 1;
  return law.W(I1, I2);
}
}  // namespace

TEST(Laws, TensionMatchesFiniteDifferenceOfEnergy) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-0.2, 0.2);
  for (const auto& law : all_laws()) {
    for (int trial = 0; trial < 20; ++trial) {
      const double A[3] = {1.0 + U(rng), 0.8 + U(rng), 0.3 * U(rng)};  // SPD reference metric
      const double g[3] = {U(rng), U(rng), 0.5 * U(rng)};
      const double a[3] = {A[0] + 2 * g[0], A[1] + 2 * g[1], A[2] + 2 * g[2]};
      double S[3];
      law.tension(A, a, S);
      // dW/dgamma_rr = S^rr, dW/dgamma_ss = S^ss, dW/d(gamma_rs = gamma_sr together) = 2 S^rs
      const double h = 1e-5;
      double fd[3];
      for (int c = 0; c < 3; ++c) {
        double gp[3] = {g[0], g[1], g[2]}, gm[3] = {g[0], g[1], g[2]};
        gp[c] += h;
        gm[c] -= h;
        fd[c] = (W_of_gamma(law, A, gp) - W_of_gamma(law, A, gm)) / (2 * h);
      }
      const double scale = std::max({std::abs(S[0]), std::abs(S[1]), std::abs(S[2])});
      // central difference: truncation O(h^2 W''') ~ 1e-10, round-off eps W / h ~ 1e-11 -> 1e-7 is safe
      EXPECT_NEAR(S[0], fd[0], 1e-7 * scale) << law.name();
      EXPECT_NEAR(S[1], fd[1], 1e-7 * scale) << law.name();
      EXPECT_NEAR(2 * S[2], fd[2], 1e-7 * scale) << law.name();
    }
  }
}

TEST(Laws, ZeroEnergyAndTensionAtRest) {
  for (const auto& law : all_laws()) {
    EXPECT_NEAR(law.W(0, 0), 0.0, 1e-15) << law.name();  // exact arithmetic up to one rounding
    const double A[3] = {1.2, 0.9, 0.1};
    double S[3];
    law.tension(A, A, S);
    for (double s : S) EXPECT_NEAR(s, 0.0, 1e-14) << law.name();  // cancellation of O(1) terms
  }
}

TEST(Laws, SmallStrainModuliMatchClaimedGsAndNu) {
  // Linearised: S = 2 Gs [gamma + nu/(1-nu) tr(gamma) I] for A = I (paper Eq. 24).
  for (const auto& law : all_laws()) {
    const double eps = 1e-7;
    const double A[3] = {1, 1, 0};
    const double g[3] = {0.3 * eps, -0.7 * eps, 0.4 * eps};
    const double a[3] = {1 + 2 * g[0], 1 + 2 * g[1], 2 * g[2]};
    double S[3];
    law.tension(A, a, S);
    const double Gs = law.Gs(), nu = law.nu_s(), tr = g[0] + g[1];
    const double Sl[3] = {2 * Gs * (g[0] + nu / (1 - nu) * tr), 2 * Gs * (g[1] + nu / (1 - nu) * tr),
                          2 * Gs * g[2]};
    // the nonlinear remainder is O(eps^2) relative to O(eps): relative error ~ 1e-7 (+ round-off 1e-9)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(S[c], Sl[c], 1e-6 * std::abs(Gs * eps)) << law.name() << c;
  }
  EXPECT_DOUBLE_EQ(make_law("nh", 1).nu_s(), 0.5);          // K_s/G_s = 3
  EXPECT_DOUBLE_EQ(make_law("skalak", 1, 0, 1).nu_s(), 0.5);  // K_s/G_s = 1 + 2C = 3
}

TEST(Laws, PrincipalTensionsMatchClosedForms) {
  const double Gs = 1.3, nu = 0.3, C = 2.5;
  const auto gh = make_law("gh", Gs, nu), nh = make_law("nh", Gs), sk = make_law("skalak", Gs, 0, C);
  for (double l1 : {0.7, 1.0, 1.3, 2.1})
    for (double l2 : {0.8, 1.1, 1.9}) {
      double T1, T2;
      // closed forms (Barthes-Biesel et al. 2002; docs/shell.md §2.3)
      nh.principal_tensions(l1, l2, T1, T2);
      EXPECT_NEAR(T1, Gs / (l1 * l2) * (l1 * l1 - 1 / (l1 * l2 * l1 * l2)), 1e-13 * Gs * 10);
      sk.principal_tensions(l1, l2, T1, T2);
      EXPECT_NEAR(T1, Gs * l1 / l2 * (l1 * l1 - 1 + C * l2 * l2 * (l1 * l1 * l2 * l2 - 1)), 1e-12 * Gs * 100);
      gh.principal_tensions(l1, l2, T1, T2);
      EXPECT_NEAR(T1, Gs * l1 / (l2 * (1 - nu)) * (l1 * l1 - 1 + nu * (l2 * l2 - 1)), 1e-12 * Gs * 10);
      // push-forward of the 2nd PK tension from tension(): T1 = l1^2 S^11 / (l1 l2) with A = I
      for (const auto* law : {&gh, &nh, &sk}) {
        const double A[3] = {1, 1, 0}, a[3] = {l1 * l1, l2 * l2, 0};
        double S[3];
        law->tension(A, a, S);
        law->principal_tensions(l1, l2, T1, T2);
        EXPECT_NEAR(T1, l1 * l1 * S[0] / (l1 * l2), 1e-12 * (1 + std::abs(T1))) << law->name();
        EXPECT_NEAR(T2, l2 * l2 * S[1] / (l1 * l2), 1e-12 * (1 + std::abs(T2))) << law->name();
      }
    }
}

TEST(Laws, UniaxialAndEquibiaxialClosedForms) {
  const double Gs = 1.0, nu = 0.4, C = 1.0;
  const auto gh = make_law("gh", Gs, nu), nh = make_law("nh", Gs), sk = make_law("skalak", Gs, 0, C);
  for (double lam : {1.05, 1.5, 2.0}) {
    double T1, T2;
    // equibiaxial: NH T = Gs(1 - lam^-6); SK T = Gs[lam^2 - 1 + C lam^2 (lam^4 - 1)];
    // GH T = Gs (1+nu)/(1-nu) (lam^2 - 1)
    nh.principal_tensions(lam, lam, T1, T2);
    EXPECT_NEAR(T1, Gs * (1 - std::pow(lam, -6)), 1e-13);
    sk.principal_tensions(lam, lam, T1, T2);
    EXPECT_NEAR(T1, Gs * (lam * lam - 1 + C * lam * lam * (std::pow(lam, 4) - 1)), 1e-12);
    gh.principal_tensions(lam, lam, T1, T2);
    EXPECT_NEAR(T1, Gs * (1 + nu) / (1 - nu) * (lam * lam - 1), 1e-12);
    // uniaxial tension (T2 = 0): find l2 by bisection, compare with the closed forms
    auto l2_of = [&](const MembraneLaw& law) {
      double lo = 0.05, hi = 1.0;
      for (int it = 0; it < 200; ++it) {
        const double mid = 0.5 * (lo + hi);
        double a, b;
        law.principal_tensions(lam, mid, a, b);
        (b > 0 ? hi : lo) = mid;
      }
      return 0.5 * (lo + hi);
    };
    // bisection to 2^-200: l2 exact to round-off; tolerances 1e-12 (l2) and 1e-10 (T1 ~ 1-10)
    const double l2nh = l2_of(nh);
    EXPECT_NEAR(l2nh, 1 / std::sqrt(lam), 1e-12);                        // NH: l2 = l1^-1/2
    nh.principal_tensions(lam, l2nh, T1, T2);
    EXPECT_NEAR(T1, Gs * (lam * lam - 1 / lam) / std::sqrt(lam), 1e-10);  // NH uniaxial
    if (1 - nu * (lam * lam - 1) > 0.05) {  // GH has a uniaxial state only while l2^2 > 0
      const double l2gh = l2_of(gh);
      EXPECT_NEAR(l2gh, std::sqrt(1 - nu * (lam * lam - 1)), 1e-12);  // GH: l2^2 - 1 = -nu (l1^2 - 1)
      gh.principal_tensions(lam, l2gh, T1, T2);
      EXPECT_NEAR(T1, Gs * (1 + nu) * lam / l2gh * (lam * lam - 1), 1e-10);  // GH uniaxial
    }
  }
}

TEST(Laws, UnknownNameThrows) { EXPECT_THROW(make_law("foo", 1), std::invalid_argument); }

TEST(Laws, InvariantDerivativesMatchFiniteDifferences) {
  for (const auto& law : all_laws())
    for (double I1 : {-0.3, 0.2, 1.5})
      for (double I2 : {-0.4, 0.1, 2.0}) {
        const double h = 1e-5;
        const double fd1 = (law.W(I1 + h, I2) - law.W(I1 - h, I2)) / (2 * h);
        const double fd2 = (law.W(I1, I2 + h) - law.W(I1, I2 - h)) / (2 * h);
        const double fd11 = (law.W1(I1 + h, I2) - law.W1(I1 - h, I2)) / (2 * h);
        const double fd12 = (law.W1(I1, I2 + h) - law.W1(I1, I2 - h)) / (2 * h);
        const double fd22 = (law.W2(I1, I2 + h) - law.W2(I1, I2 - h)) / (2 * h);
        // central differences, h = 1e-5: truncation ~1e-10 x third derivative, round-off ~1e-11 W/h
        const double tol = 1e-7 * law.Gs();
        EXPECT_NEAR(law.W1(I1, I2), fd1, tol) << law.name();
        EXPECT_NEAR(law.W2(I1, I2), fd2, tol) << law.name();
        EXPECT_NEAR(law.W11(I1, I2), fd11, tol) << law.name();
        EXPECT_NEAR(law.W12(I1, I2), fd12, tol) << law.name();
        EXPECT_NEAR(law.W22(I1, I2), fd22, 10 * tol) << law.name();  // larger 4th derivative near I2 = -0.4
      }
}

TEST(Laws, MooneyRivlinIsTheThinIncompressibleSheet) {
  // 3-D incompressible Mooney-Rivlin, W3 = C1 (I1 - 3) + C2 (I2 - 3), lambda3 = 1/(l1 l2),
  // integrated over the thickness h: W_s = h W3 with G_s = 2 h (C1 + C2), Psi = C2/(C1 + C2).
  const double Gs = 0.9, Psi = 0.3, h = 0.1;
  const double C1 = (1 - Psi) * Gs / (2 * h), C2 = Psi * Gs / (2 * h);
  const MembraneLaw mr = make_law("mr", Gs, 0, Psi);
  auto W3 = [&](double l1, double l2) {
    const double l3 = 1 / (l1 * l2);
    const double i1 = l1 * l1 + l2 * l2 + l3 * l3;
    const double i2 = l1 * l1 * l2 * l2 + l2 * l2 * l3 * l3 + l3 * l3 * l1 * l1;
    return h * (C1 * (i1 - 3) + C2 * (i2 - 3));
  };
  for (double l1 : {0.8, 1.2, 1.9})
    for (double l2 : {0.9, 1.4}) {
      const double I1 = l1 * l1 + l2 * l2 - 2, I2 = l1 * l1 * l2 * l2 - 1;
      EXPECT_NEAR(mr.W(I1, I2), W3(l1, l2), 1e-12 * (1 + W3(l1, l2)));  // same algebra: round-off
      // principal tension T1 = (1/l2) dW/dl1 (energy per reference area), central difference
      const double d = 1e-6;
      const double T1fd = (W3(l1 + d, l2) - W3(l1 - d, l2)) / (2 * d) / l2;
      double T1, T2;
      mr.principal_tensions(l1, l2, T1, T2);
      EXPECT_NEAR(T1, T1fd, 1e-7 * (1 + std::abs(T1)));
    }
  EXPECT_DOUBLE_EQ(mr.nu_s(), 0.5);
}
