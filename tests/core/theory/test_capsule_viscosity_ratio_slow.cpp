// capsflow with a viscosity ratio λ ≠ 1 against the small-deformation theory (docs/small-deformation.md
// §5): the tensionless-drop velocity at t = 0 and the transient D(t), whose time scale grows
// linearly with λ while its steady value does not depend on λ. A few CPU minutes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "capsflow/core/theory/small_deformation.hpp"
#include "capsule_run.hpp"

using namespace capsflow;


TEST(CapsuleViscosityRatioSlow, UnloadedSphereMovesLikeATensionlessDrop) {
  // At t = 0 the membrane carries no load: the exact surface velocity is Ω×x + 5/(2λ+3) E x, for
  // any λ (docs/small-deformation.md §5.2), a test of the second-kind solve alone.
  for (const char* lambda : {"0.2", "5"})
    for (const char* flow : {"planar_hyperbolic", "simple_shear"}) {
      const Scene s = parse_scene(default_scene_toml(), "drop",
                                  {"mesh.level=3", "mesh.shape=\"sphere\"", "wall.model=\"membrane\"",
                                   "fluid.backend=\"direct\"", std::string("flow.type=\"") + flow + "\"",
                                   std::string("fluid.viscosity_ratio=") + lambda});
      const SurfaceMesh ref = make_reference_mesh(s.mesh);
      CapsuleDynamics dyn(s, ref);
      Points v;
      dyn.velocity(ref.vertices, v);
      double err = 0, scale = 0;
      for (Eigen::Index i = 0; i < ref.vertices.rows(); ++i) {
        const Vec3 x = ref.vertices.row(i).transpose();
        const Vec3 exact = theory::initial_surface_velocity(s.flow.gradient, std::atof(lambda), x);
        err = std::max(err, (v.row(i).transpose() - exact).norm());
        scale = std::max(scale, exact.norm());
      }
      std::printf("λ = %s, %s, level 3: max |v − v_drop| / max |v_drop| = %.3e\n", lambda, flow, err / scale);
      // With no load v1 = v∞ exactly (at λ = 1 the error is 0): what remains is the double layer's
      // level-3 error on the strain mode E x, the n = 2 interior potential flow (3.2e-3 on flat
      // facets, docs/boundary-integral.md §4.7.4). Measured 1.3e-3 … 4.5e-3 (λ = 0.2, 5; both
      // flows); 8e-3 leaves margin. A solve that ignored λ would be off by |1 − 5/(2λ + 3)| ≥ 0.32.
      EXPECT_LT(err / scale, 8e-3) << "λ = " << lambda << ", " << flow;
    }
}

TEST(CapsuleViscosityRatioSlow, TransientFollowsTheTheory) {
  // NH membrane sphere, level 3, Ca_s = 0.005; D at t/τ = 0.5, 1, 2 with τ the theory's
  // (2.65 Ca at λ = 0.2, 11.0 Ca at λ = 5).
  struct Case {
    const char* lambda;
    const char* flow;
  };
  for (const Case c : {Case{"0.2", "planar_hyperbolic"}, Case{"5", "planar_hyperbolic"}, Case{"5", "simple_shear"}}) {
    const double lambda = std::atof(c.lambda);
    const theory::SmallDeformation th(1 / 0.005, 0.5, lambda);
    const double tau = th.relaxation_time();
    const auto run = test::run_capsule({"mesh.level=3", "wall.law=\"nh\"", "flow.ca_s=0.005",
                                        std::string("flow.type=\"") + c.flow + "\"",
                                        std::string("fluid.viscosity_ratio=") + c.lambda},
                                       {0.5 * tau, tau, 2 * tau});
    const Mat3& L = run.scene.flow.gradient;
    for (const auto& s : run.samples) {
      const InPlaneShape e = th.in_plane_shape(L, flow_plane(L), s.t);
      std::printf("λ = %s, %s, level 3, Ca_s 0.005, t/τ = %.1f: D = %.6e, theory %.6e (%+.4f), θ = %.3f°\n", c.lambda,
                  c.flow, s.t / tau, s.shape.D, e.D, s.shape.D / e.D - 1, s.shape.theta * 180 / M_PI);
      // λ = 1 at level 3: −0.6 % (mesh, O(h²)) and −0.01 % (theory, O(Ca²)). Measured at λ = 0.2 and 5:
      // −0.42 % … −0.60 % over t/τ = 0.5–2, both flows: the same mesh bias as at λ = 1 (the double
      // layer adds no visible error of its own). 1 % = that bias + 0.4 %; a run whose time scale
      // ignored λ would be off by 29 % (λ = 0.2) and 89 % (λ = 5) at t = τ/2.
      EXPECT_NEAR(s.shape.D / e.D, 1.0, 0.01) << "λ = " << c.lambda << ", " << c.flow << ", t/τ = " << s.t / tau;
    }
  }
}
