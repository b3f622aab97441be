// Refinement studies of the forward static mode (label: slow, minutes).
#include <gtest/gtest.h>

#include <cstdio>

#include "support/benchmarks.hpp"

using namespace capsflow::shell::testing;

TEST(SlowBenchmarks, ScordelisLoConvergence) {
  double prev = 0;
  for (int n : {8, 16, 32, 64}) {
    const double w = scordelis_lo(n);
    std::printf("Scordelis-Lo %2dx%-2d: %.5f (%.2f%% of 0.3024)\n", n, n, w, 100 * w / 0.3024);
    EXPECT_GT(w, prev);  // monotone convergence from below (MITC3 is stiff)
    prev = w;
  }
  EXPECT_NEAR(prev / 0.3024, 1.0, 0.01);  // measured -0.7% at 64x64
}

TEST(SlowBenchmarks, PinchedCylinderConvergence) {
  double prev = 0;
  for (int n : {16, 32, 64}) {
    const double w = pinched_cylinder(n);
    std::printf("pinched cylinder %2dx%-2d: %.5e (%.2f%% of 1.8248e-5)\n", n, n, w, 100 * w / 1.8248e-5);
    EXPECT_GT(w, prev);
    prev = w;
  }
  EXPECT_NEAR(prev / 1.8248e-5, 1.0, 0.03);  // measured -0.6% at 64x64 (the octant's reference mesh)
}

TEST(SlowBenchmarks, PinchedHemisphereConvergence) {
  for (bool hole : {true, false}) {
    double prev = 0;
    const double ref = hole ? 0.094 : 0.0924;
    for (int n : {8, 16, 32, 64}) {
      const double w = pinched_hemisphere(n, hole);
      std::printf("hemisphere %s %2dx%-2d: %.5f (%.2f%% of %.4f)\n", hole ? "18deg hole" : "closed    ", n, n, w,
                  100 * w / ref, ref);
      EXPECT_GT(w, prev);
      prev = w;
    }
    EXPECT_NEAR(prev / ref, 1.0, 0.01);  // measured -0.7% (hole) and -0.2% (closed) at 64x64
  }
}

TEST(SlowBenchmarks, PlatesConvergenceAndMeshPattern) {
  for (int pattern : {1, 0})
    for (int n : {4, 8, 16, 32}) {
      const double c = plate_center_ratio(true, 1e-3, n, pattern), s = plate_center_ratio(false, 1e-3, n, pattern);
      std::printf("plate h/L=1e-3 pattern %d %2dx%-2d: clamped %.5f  ss %.5f\n", pattern, n, n, c, s);
      if (n == 32) {
        EXPECT_NEAR(c, 1.0, pattern == 1 ? 0.005 : 0.02);  // measured 0.9974 / 0.984
        EXPECT_NEAR(s, 1.0, pattern == 1 ? 0.005 : 0.015);  // measured 0.9989 / 0.989
      }
    }
}

TEST(SlowBenchmarks, RollupConvergence) {
  double prev_err = 1e9;
  for (int nx : {12, 24, 48}) {
    const auto pts = cantilever_rollup(nx, 1, 20);
    ASSERT_EQ(pts.size(), 20u);
    const auto& p = pts.back();
    const double err = std::hypot(p.U - p.U_exact, p.W - p.W_exact) / 12.0;
    std::printf("roll-up %2d elements along: full circle tip U %.4f W %.4f (exact -12, 0): error %.2e L\n", nx,
                p.U, p.W, err);
    EXPECT_LT(err, prev_err / 3);  // O(dx^2): measured ratio ~3.6
    prev_err = err;
  }
}

TEST(SlowBenchmarks, SlitAnnularPlate) {
  // Sze, Liu & Lo (2004), S4R 10x80: at full load W_A (inner) 13.891, W_B (outer) 17.528;
  // at half load 10.468 / 13.768.
  const auto pts = slit_annular_plate(10, 80, 40);
  ASSERT_EQ(pts.size(), 40u);
  for (const auto& p : pts) EXPECT_GE(p.newton, 0) << p.f;
  const auto& h = pts[19];
  const auto& f = pts[39];
  std::printf("slit annular plate 10x80 (x2 triangles): f=0.5 WA %.3f (10.468) WB %.3f (13.768); f=1 WA %.3f (13.891) WB %.3f (17.528)\n",
              h.WA, h.WB, f.WA, f.WB);
  // MITC3 triangles are stiffer than the S4R quadrilaterals of the reference; measured -3.7% / -2.9%
  // at full load on this mesh and -1.7% / -1.3% on 16x128 (2.5 min, not run here)
  EXPECT_NEAR(f.WA / 13.891, 1.0, 0.05);
  EXPECT_NEAR(f.WB / 17.528, 1.0, 0.04);
  EXPECT_NEAR(h.WA / 10.468, 1.0, 0.04);
  EXPECT_NEAR(h.WB / 13.768, 1.0, 0.03);
}
