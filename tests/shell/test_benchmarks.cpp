// Forward static mode on classical shell benchmarks (fast sizes; refinement studies are in
// test_benchmarks_slow.cpp). Every computed value is printed beside its reference.
#include <gtest/gtest.h>

#include <cstdio>

#include "support/benchmarks.hpp"

using namespace capsflow::shell;
using namespace capsflow::shell::testing;

TEST(LinearBenchmarks, KirchhoffPlatesWithoutShearLocking) {
  // Centre deflection / Kirchhoff value (Timoshenko & Woinowsky-Krieger: alpha = 0.00126532
  // clamped, 0.00406235 simply supported), quarter model 16 x 16, alternating diagonals.
  for (double t : {1e-3, 1e-4}) {
    const double c = plate_center_ratio(true, t, 16, 1), s = plate_center_ratio(false, t, 16, 1);
    std::printf("plate h/L = %.0e: clamped %.5f  simply supported %.5f (of Kirchhoff)\n", t, c, s);
    EXPECT_NEAR(c, 1.0, 0.02) << t;   // measured 0.985 / 0.982: discretisation error of a 16x16 quarter
    EXPECT_NEAR(s, 1.0, 0.01) << t;   // measured 0.995
  }
  // no locking: thinning the plate 10x changes the answer by < 0.5% (a locking element loses
  // a factor ~ (h_old/h_new)^2 = 100)
  EXPECT_NEAR(plate_center_ratio(true, 1e-4, 16, 1) / plate_center_ratio(true, 1e-3, 16, 1), 1.0, 0.005);
}

TEST(LinearBenchmarks, ScordelisLoRoof) {
  const double w = scordelis_lo(32);
  std::printf("Scordelis-Lo 32x32: %.5f  (reference 0.3024; 0.3086 deep-shell)\n", w);
  EXPECT_NEAR(w / 0.3024, 1.0, 0.03);  // measured -1.6% (MITC3 converges from below)
}

TEST(LinearBenchmarks, PinchedHemisphere) {
  const double a = pinched_hemisphere(32, true), b = pinched_hemisphere(32, false);
  std::printf("pinched hemisphere 32x32: with 18 deg hole %.5f (ref 0.094), closed %.5f (ref 0.0924)\n", a, b);
  EXPECT_NEAR(a / 0.094, 1.0, 0.03);   // measured -1.9%
  EXPECT_NEAR(b / 0.0924, 1.0, 0.03);  // measured -1.7%
}

TEST(NonlinearBenchmarks, CantileverRolledIntoACircleByAnEndMoment) {
  // exact: tip at (R sin phi - L, R (1 - cos phi)), R = L/phi, phi = 2 pi f
  const auto pts = cantilever_rollup(24, 1, 20);
  ASSERT_EQ(pts.size(), 20u);
  for (const auto& p : pts) {
    EXPECT_GE(p.newton, 0) << "load step " << p.f << " did not converge";
    const double err = std::hypot(p.U - p.U_exact, p.W - p.W_exact) / 12.0;
    if (std::abs(p.f - 0.25) < 1e-9 || std::abs(p.f - 0.5) < 1e-9 || std::abs(p.f - 1.0) < 1e-9)
      std::printf("roll-up f = %.2f: tip U %.4f (exact %.4f)  W %.4f (exact %.4f)  newton %d\n", p.f, p.U,
                  p.U_exact, p.W, p.W_exact, p.newton);
    EXPECT_LT(err, 0.015) << p.f;  // measured <= 1.2% of L with 24 facets: chord error O(dx^2)
  }
}

TEST(NonlinearBenchmarks, CantileverUnderEndShearForce) {
  // Sze, Liu & Lo (2004) reference (S4R 16x1): P = 2: W 4.933, -U 1.604; P = 4: W 6.698, -U 3.286.
  // Own oracle: the inextensible Euler-Bernoulli elastica (shooting), P = 4: W 6.6996, -U 3.2894.
  const auto pts = cantilever_end_shear(20, 1, 10);
  ASSERT_EQ(pts.size(), 10u);
  const double EI = 1.2e6 * 0.1 * 0.1 * 0.1 / 12;
  for (const auto& p : pts) {
    EXPECT_GE(p.newton, 0) << p.P;
    const auto [We, Ue] = elastica_tip_load(p.P, EI, 10.0);
    EXPECT_NEAR(p.W / We, 1.0, 0.01) << p.P;   // measured +0.05% at P = 4
    EXPECT_NEAR(p.mU / Ue, 1.0, 0.02) << p.P;  // measured +0.08% at P = 4
  }
  std::printf("end shear P = 2: W %.4f (Sze 4.933)  -U %.4f (Sze 1.604)\n", pts[4].W, pts[4].mU);
  std::printf("end shear P = 4: W %.4f (Sze 6.698)  -U %.4f (Sze 3.286)\n", pts[9].W, pts[9].mU);
  EXPECT_NEAR(pts[9].W / 6.698, 1.0, 0.01);
  EXPECT_NEAR(pts[9].mU / 3.286, 1.0, 0.01);
}

TEST(StaticSolver, ConjugateGradientOptionMatchesSparseLdlt) {
  // clamped quarter plate, h/L = 1e-2: both linear solvers must give the same deflection
  double w[2];
  for (int k = 0; k < 2; ++k) {
    const double L = 1.0, E = 1e6, nu = 0.3, h = 1e-2;
    Mesh m = plate(L / 2, L / 2, 8, 8, 1);
    StaticShell s(m.X, m.T, Points(), hooke(E, nu, h), h, nu);
    for (Eigen::Index i = 0; i < m.X.rows(); ++i) {
      const double x = m.X(i, 0), y = m.X(i, 1);
      if (x < 1e-9 || y < 1e-9) {
        for (int c = 0; c < 3; ++c) s.fix_translation(i, c);
        s.fix_rotations(i);
      }
      if (x > L / 2 - 1e-9) { s.fix_translation(i, 0); s.fix_rotation_about(i, Vec3::UnitY()); }
      if (y > L / 2 - 1e-9) { s.fix_translation(i, 1); s.fix_rotation_about(i, Vec3::UnitX()); }
    }
    s.set_forces(pressure_loads(m, Vec3(0, 0, -1.0)));
    StaticOptions o;
    o.use_cg = (k == 1);
    s.solve_linear(o);
    w[k] = s.displacement()(m.X.rows() - 1, 2);
  }
  EXPECT_NEAR(w[1] / w[0], 1.0, 1e-6);  // CG tolerance 1e-12 on a system with cond ~ 1e6
}
