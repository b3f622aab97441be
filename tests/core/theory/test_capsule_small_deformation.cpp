// capsflow against the small-deformation theory (docs/small-deformation.md §8) on short, coarse
// runs: a membrane sphere released at t = 0 into planar hyperbolic flow and simple shear at
// Ca_s = 0.01, λ = 1. The theory is independent of the code under test (closed forms); the run's
// relative error is O(h²) (mesh: 2–5 % at level 2, 4× less at level 3, perf/RESULTS.md §2.3) plus
// O(Ca²) (theory: 0.05 % here).
#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/theory/small_deformation.hpp"
#include "capsule_run.hpp"

using namespace capsflow;

TEST(CapsuleSmallDeformation, PlanarHyperbolicTransientFollowsTheTheory) {
  const theory::SmallDeformation th(1 / 0.01, 0.5, 1.0);  // NH: ν_s = 1/2
  const double tau = th.relaxation_time();                 // 0.040
  const auto run = test::run_capsule({"mesh.level=2", "wall.law=\"nh\"", "flow.ca_s=0.01",
                                      "flow.type=\"planar_hyperbolic\""},
                                     {0.25 * tau, tau, 3 * tau});
  const Mat3& L = run.scene.flow.gradient;
  for (const auto& s : run.samples) {
    const InPlaneShape e = th.in_plane_shape(L, flow_plane(L), s.t);
    // Measured −1.2 %, −1.9 %, −2.2 % (level 2): 3 % bounds the mesh error with margin; a 10 %
    // error in the theory's time scale would move D(τ) by 5 %, in its steady value by 10 %.
    EXPECT_NEAR(s.shape.D / e.D, 1.0, 0.03) << "t/τ = " << s.t / tau << ": D = " << s.shape.D << ", theory " << e.D;
    EXPECT_NEAR(s.shape.theta, 0.0, 1e-6) << "t/τ = " << s.t / tau;  // symmetry: the axis stays on x1
  }
}

TEST(CapsuleSmallDeformation, SimpleShearTiltsAt45DegreesAndTankTreads) {
  // A GH membrane with ν_s = 0 (steady D = 2.5 Ca_s, not NH's 25/12 Ca_s).
  const theory::SmallDeformation th(1 / 0.01, 0.0, 1.0);
  const double tau = th.relaxation_time();  // 0.055
  const auto run = test::run_capsule({"mesh.level=2", "wall.law=\"gh\"", "wall.poisson=0", "flow.ca_s=0.01",
                                      "flow.type=\"simple_shear\""},
                                     {tau, 4 * tau});
  const Mat3& L = run.scene.flow.gradient;
  for (const auto& s : run.samples) {
    const InPlaneShape e = th.in_plane_shape(L, flow_plane(L), s.t);
    // Measured −3.0 % (τ) and −5.0 % (4τ) at level 2, −0.8 % and −1.3 % at level 3: the mesh error,
    // larger than NH's for this more compressible membrane; 6 % bounds it. NH's steady D would be
    // 17 % lower (25/12 against 5/2 Ca_s).
    EXPECT_NEAR(s.shape.D / e.D, 1.0, 0.06) << "t/τ = " << s.t / tau << ": D = " << s.shape.D << ", theory " << e.D;
    // θ = 45° at first order; the neglected co-rotation tilts it by O(Ca): measured 1.4° at 4τ here
    // (GH ν_s = 0 at levels 2 and 3; NH: 1.14°), mesh-independent (perf/RESULTS.md §2.3).
    EXPECT_NEAR(s.shape.theta * 180 / M_PI, 45.0, 2.0) << "t/τ = " << s.t / tau;
    // The membrane turns with the vorticity, 1/2, up to O(Ca²): measured 0.4994 at 4τ.
    EXPECT_NEAR(s.tank_treading, theory::SmallDeformation::tank_treading_rate(L, flow_plane(L)), 2e-3)
        << "t/τ = " << s.t / tau;
  }
}
