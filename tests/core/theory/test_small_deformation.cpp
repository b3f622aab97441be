// The small-deformation theory (theory/small_deformation) against what is known without it:
// published closed forms (Barthès-Biesel 1980, Taylor 1932, the tensionless drop), the single layer
// of its modes by direct quadrature, the membrane load as the variation of the Hooke energy by
// finite differences, and the mode equations integrated step by step.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/LU>

#include "capsflow/core/bie/quadrature.hpp"  // GaussLegendre only
#include "capsflow/core/theory/small_deformation.hpp"

using namespace capsflow;
using namespace capsflow::theory;

namespace {
const Mat3 kHyperbolic = Vec3(1, 0, -1).asDiagonal();
Mat3 simple_shear() {
  Mat3 L = Mat3::Zero();
  L(0, 1) = 1;
  return L;
}
Mat3 random_trace_free_symmetric(std::mt19937& rng) {
  std::normal_distribution<double> n;
  Mat3 A;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) A(i, j) = n(rng);
  const Mat3 S = A + A.transpose();  // not A = A + Aᵀ: Eigen would read A while writing it
  return S - S.trace() / 3 * Mat3::Identity();
}
// Product rule on the unit sphere in polar coordinates (θ, φ) about the pole p: Gauss–Legendre in
// θ ∈ (0, π), trapezoid in φ. The Jacobian sin θ cancels the 1/|x − y| of a Stokeslet at p.
template <class F>
void sphere_quadrature(const Vec3& p, int n_theta, int n_phi, F&& f) {
  const Vec3 t1 = p.unitOrthogonal(), t2 = p.cross(t1);
  const GaussLegendre rule(n_theta);  // on [0, 1]
  for (int i = 0; i < n_theta; ++i) {
    const double theta = M_PI * rule.x[i], wt = M_PI * rule.w[i] * std::sin(theta);
    for (int j = 0; j < n_phi; ++j) {
      const double phi = 2 * M_PI * j / n_phi;
      const Vec3 y = std::cos(theta) * p + std::sin(theta) * (std::cos(phi) * t1 + std::sin(phi) * t2);
      f(y, wt * 2 * M_PI / n_phi);
    }
  }
}
// The two degree-2 modes of docs/small-deformation.md §3 at x̂ for the tensor T.
Vec3 radial_mode(const Mat3& T, const Vec3& x) { return x.dot(T * x) * x; }
Vec3 tangential_mode(const Mat3& T, const Vec3& x) { return T * x - x.dot(T * x) * x; }
}  // namespace

TEST(SmallDeformationTheory, SteadyShapeIsBarthesBieselsForAnyViscosityRatio) {
  // Barthès-Biesel (1980), Barthès-Biesel & Rallison (1981): in simple shear D = (25/4) μγ̇a/E_s for
  // a neo-Hookean membrane (E_s = 3 G_s), i.e. (25/12)/G_s, and in general (5/4)(2 + ν_s)/(1 + ν_s)/G_s,
  // independent of λ. Planar hyperbolic flow has twice the strain rate: twice D.
  const double G = 200;  // Ca_s = 0.005
  for (const double lambda : {0.01, 0.2, 1.0, 5.0, 100.0}) {
    const SmallDeformation nh(G, 0.5, lambda);
    const double t_long = 60 * nh.relaxation_time();
    const Mat3 L = simple_shear();
    EXPECT_NEAR(nh.in_plane_shape(L, flow_plane(L), t_long).D, 25.0 / 12 / G, 1e-12) << "λ = " << lambda;
    const Mat3 H = kHyperbolic;
    EXPECT_NEAR(nh.in_plane_shape(H, flow_plane(H), t_long).D, 25.0 / 6 / G, 1e-12) << "λ = " << lambda;
    for (const double nu : {-0.5, 0.0, 0.3, 0.9}) {
      const SmallDeformation gh(G, nu, lambda);
      // e^{−60} of the transient is left at t_long; 1e-12 absolute is round-off on D ~ 1e-2.
      EXPECT_NEAR(gh.in_plane_shape(L, flow_plane(L), 60 * gh.relaxation_time()).D,
                  1.25 * (2 + nu) / (1 + nu) / G, 1e-12)
          << "ν_s = " << nu << ", λ = " << lambda;
    }
  }
}

TEST(SmallDeformationTheory, InitialRateIsTheTensionlessDrops) {
  // At t = 0 the membrane carries no load: the sphere moves like a drop without surface tension,
  // whose interface velocity is Ω×x + 5/(2λ + 3) E x (Taylor 1932; Rallison, Annu. Rev. Fluid Mech.
  // 16, 1984). λ = 1: the affine flow itself (D13 = tanh t ≈ t in planar hyperbolic flow).
  for (const double lambda : {0.01, 0.1, 1.0, 10.0, 100.0}) {
    const SmallDeformation th(100, 0.5, lambda);
    EXPECT_NEAR(th.initial_rate(), 5 / (2 * lambda + 3), 1e-14) << lambda;
    // The closed-form transient has the same slope: forward difference, error ~ h c'' ≪ 1e-6.
    const double h = 1e-9;
    EXPECT_NEAR(th.amplitude(h) / h, 5 / (2 * lambda + 3), 1e-6) << lambda;
    EXPECT_NEAR(th.amplitude(0), 0.0, 1e-15 * th.steady_amplitude());  // w0 + w1 = 1 to round-off
  }
  const Vec3 x(0.36, -0.48, 0.8);
  EXPECT_LT((initial_surface_velocity(kHyperbolic, 1.0, x) - kHyperbolic * x).norm(), 1e-15);
  EXPECT_LT((initial_surface_velocity(simple_shear(), 1.0, x) - simple_shear() * x).norm(), 1e-15);
  // Large λ: the interior resists, only the rotation is left (the rigid sphere's Ω×x).
  const Vec3 u = initial_surface_velocity(simple_shear(), 1e9, x);
  EXPECT_LT((u - 0.5 * Vec3(x.y(), -x.x(), 0)).norm(), 1e-8);
}

TEST(SmallDeformationTheory, ViscousResistanceGivesTaylorsDrop) {
  // The hydrodynamic half of the theory, R(λ), checked on the classical drop: an interface with
  // uniform tension σ has the normal load 4σ Y_F (Laplace, degree 2) and no tangential stiffness.
  // Eliminating the tangential mode gives dF/dt = a − b F with, in simple shear, D = F/2 =
  // (19λ + 16)/(16(λ + 1)) μγ̇a/σ (Taylor 1932) and the relaxation rate
  // b = 40(λ + 1)/((2λ + 3)(19λ + 16)) σ/(μa) (Cox 1969; Rallison 1984).
  const double sigma = 50;
  for (const double lambda : {0.01, 0.2, 1.0, 5.0, 100.0}) {
    const Mat2 Rinv = viscous_resistance(lambda).inverse();
    const double a = kRigidSphereTraction * (Rinv(0, 0) + Rinv(0, 1));
    const double b = Rinv(0, 0) * 4 * sigma;
    EXPECT_NEAR(0.5 * a / b, (19 * lambda + 16) / (16 * (lambda + 1)) / sigma, 1e-14) << lambda;
    EXPECT_NEAR(b, 40 * (lambda + 1) / ((2 * lambda + 3) * (19 * lambda + 16)) * sigma, 1e-10 * sigma) << lambda;
  }
}

TEST(SmallDeformationTheory, SingleLayerOfTheModesMatchesQuadrature) {
  // λ = 1: no interior/exterior distinction, the velocity of a load q is the single layer
  // S[q] = (1/8π) ∫ G·q dS, so R(1)⁻¹ must be S on the two modes, here by direct quadrature at a
  // random point (polar rule about it, 160 × 160 points: the integrand is smooth in (θ, φ)).
  std::mt19937 rng(7);
  const Mat3 T = random_trace_free_symmetric(rng);
  const Vec3 p = Vec3(0.3, -0.5, 0.81).normalized();
  const Mat2 Rinv = viscous_resistance(1.0).inverse();
  for (int mode = 0; mode < 2; ++mode) {
    Vec3 u = Vec3::Zero();
    sphere_quadrature(p, 160, 160, [&](const Vec3& y, double w) {
      const Vec3 q = mode == 0 ? radial_mode(T, y) : tangential_mode(T, y);
      const Vec3 r = p - y;
      const double d = r.norm();
      u += w * (q / d + r * (r.dot(q) / (d * d * d))) / (8 * M_PI);
    });
    const Vec3 expected = Rinv(0, mode) * radial_mode(T, p) + Rinv(1, mode) * tangential_mode(T, p);
    // Spectral convergence in θ, φ: the 160-point rule is at round-off (1e-10 leaves margin).
    EXPECT_LT((u - expected).norm(), 1e-10 * T.norm()) << "mode " << mode << ": " << u.transpose()
                                                        << " vs " << expected.transpose();
  }
  // The published numbers: S maps the radial mode to (4/35, 2/35), the tangential to (3/35, 5/35).
  EXPECT_NEAR(Rinv(0, 0), 4.0 / 35, 1e-15);
  EXPECT_NEAR(Rinv(1, 1), 5.0 / 35, 1e-15);
}

TEST(SmallDeformationTheory, MembraneStiffnessIsTheHookeEnergysVariation) {
  // K is the load (= δE/δu) of the linear 2-D Hooke membrane, E = ½ ∫ (2G e:e + (K_s − G)(tr e)²) dS,
  // e = P sym(∇u) P. Here e comes from central differences of u extended as u(x/|x|), E from a product
  // rule, and ∫ q·δu dS must equal the directional derivative of E.
  std::mt19937 rng(11);
  const Mat3 F = random_trace_free_symmetric(rng), H = random_trace_free_symmetric(rng);
  const Mat3 dF = random_trace_free_symmetric(rng), dH = random_trace_free_symmetric(rng);
  const double G = 1.0;
  for (const double nu : {-0.4, 0.3, 0.5}) {
    const double Ks = G * (1 + nu) / (1 - nu), Lam = Ks - G;
    auto u = [](const Mat3& A, const Mat3& B, const Vec3& y) {
      const Vec3 x = y.normalized();
      return Vec3(radial_mode(A, x) + tangential_mode(B, x));
    };
    auto energy = [&](const Mat3& A, const Mat3& B) {
      double e_sum = 0;
      sphere_quadrature(Vec3::UnitZ(), 30, 60, [&](const Vec3& x, double w) {
        Mat3 grad;  // grad(i, j) = ∂_i u_j
        const double h = 1e-5;
        for (int i = 0; i < 3; ++i) {
          const Vec3 d = h * Vec3::Unit(i);
          grad.row(i) = ((u(A, B, x + d) - u(A, B, x - d)) / (2 * h)).transpose();
        }
        const Mat3 P = Mat3::Identity() - x * x.transpose();
        const Mat3 e = P * (0.5 * (grad + grad.transpose())) * P;
        e_sum += w * 0.5 * (2 * G * e.squaredNorm() + Lam * e.trace() * e.trace());
      });
      return e_sum;
    };
    const double eps = 1e-4;
    const double dE = (energy(F + eps * dF, H + eps * dH) - energy(F - eps * dF, H - eps * dH)) / (2 * eps);
    const Mat2 S = membrane_stiffness(G, nu);
    double work = 0;
    sphere_quadrature(Vec3::UnitZ(), 30, 60, [&](const Vec3& x, double w) {
      const Vec3 q = radial_mode(S(0, 0) * F + S(0, 1) * H, x) + tangential_mode(S(1, 0) * F + S(1, 1) * H, x);
      work += w * q.dot(u(dF, dH, x));
    });
    // Finite-difference truncation (h² ~ 1e-10 relative in e, eps² in E) and round-off ε/h ~ 1e-11:
    // 1e-7 relative leaves margin; a wrong coefficient in K changes the work by O(1).
    EXPECT_NEAR(work, dE, 1e-7 * std::abs(dE)) << "ν_s = " << nu;
  }
}

TEST(SmallDeformationTheory, ClosedFormSolvesTheModeEquations) {
  // RK4 on R y' = 5(1, 1) − K y from y = 0 against c(t); the relaxation time against the integral
  // ∫ (y∞ − y) dt = K⁻¹ R y∞ (Laplace transform at 0) — a route that needs no eigenvalues.
  for (const double lambda : {0.1, 1.0, 10.0}) {
    const double G = 100, nu = 0.5;
    const SmallDeformation th(G, nu, lambda);
    Vec2 y = Vec2::Zero();
    const double dt = 0.02 / th.rates()[1];
    double t = 0;
    for (int k = 0; k < 4000; ++k) {
      const Vec2 k1 = th.mode_rates(y), k2 = th.mode_rates(y + 0.5 * dt * k1);
      const Vec2 k3 = th.mode_rates(y + 0.5 * dt * k2), k4 = th.mode_rates(y + dt * k3);
      y += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      t += dt;
      if (k % 500 == 499) {  // RK4 at s1 dt = 0.02: error ~ (0.02)⁴ per unit time, ≪ 1e-9 c∞
        EXPECT_NEAR(y[0], th.amplitude(t), 1e-9 * th.steady_amplitude()) << "λ = " << lambda << ", t = " << t;
      }
    }
    const Vec2 y_inf = membrane_stiffness(G, nu).lu().solve(Vec2::Constant(kRigidSphereTraction));
    const Vec2 area = membrane_stiffness(G, nu).lu().solve(viscous_resistance(lambda) * y_inf);
    EXPECT_NEAR(th.relaxation_time(), area[0] / y_inf[0], 1e-12 * th.relaxation_time()) << lambda;
    EXPECT_NEAR(th.weights()[0] + th.weights()[1], 1.0, 1e-13);
    EXPECT_GT(th.rates()[0], 0);
    EXPECT_LT(th.rates()[0], th.rates()[1]);
  }
}

TEST(SmallDeformationTheory, RelaxationTimeGrowsLinearlyWithLambda) {
  // docs/small-deformation.md §5.3: τ = Ca [(16ν² + 43ν + 79) λ + 24ν² + 72ν + 96] / (16 (1 + ν)(2 + ν)):
  // linear in λ, the interior's dissipation adding to the exterior's (NH: τ = Ca (104.5 λ + 138)/60).
  const double G = 100;
  for (const double nu : {-0.5, 0.0, 0.5, 0.9})
    for (const double lambda : {0.01, 0.5, 1.0, 7.0, 100.0}) {
      const double tau = ((16 * nu * nu + 43 * nu + 79) * lambda + 24 * nu * nu + 72 * nu + 96) /
                         (16 * (1 + nu) * (2 + nu) * G);
      EXPECT_NEAR(SmallDeformation(G, nu, lambda).relaxation_time(), tau, 1e-12 * tau) << nu << " " << lambda;
    }
  // Both rates fall like 1/λ for λ → ∞ (the interior alone resists the surface motion).
  const SmallDeformation a(G, 0.5, 1e4), b(G, 0.5, 2e4);
  EXPECT_NEAR(a.rates()[0] / b.rates()[0], 2.0, 1e-3);
  EXPECT_NEAR(a.rates()[1] / b.rates()[1], 2.0, 1e-3);
}

TEST(SmallDeformationTheory, ObservablesInThePlanarHyperbolicAndSimpleShearFlows) {
  const SmallDeformation th(100, 0.5, 1.0);
  const double t = 0.03, c = th.amplitude(t);
  ASSERT_GT(c, 0);
  // Planar hyperbolic: E = diag(1, 0, −1), flow plane x1x3: D = c, θ = 0; D13 = c, D12 = D23 = c/2;
  // no vorticity, no tank-treading.
  const Mat3 H = kHyperbolic;
  const InPlaneShape h = th.in_plane_shape(H, flow_plane(H), t);
  EXPECT_NEAR(h.D, c, 1e-15);
  EXPECT_NEAR(h.theta, 0, 1e-15);
  EXPECT_NEAR((th.coordinate_taylor(H, t) - Vec3(0.5 * c, c, 0.5 * c)).norm(), 0, 1e-15);
  EXPECT_EQ(SmallDeformation::tank_treading_rate(H, flow_plane(H)), 0);
  // Simple shear: E has eigenvalues ±1/2 along (1, ±1, 0)/√2: D = c/2 at θ = 45°; the membrane turns
  // with the vorticity, 1/2 in the meter's sign (docs/conventions.md §5.6); D_ij ill-defined.
  const Mat3 L = simple_shear();
  const InPlaneShape s = th.in_plane_shape(L, flow_plane(L), t);
  EXPECT_NEAR(s.D, 0.5 * c, 1e-15);
  EXPECT_NEAR(s.theta, M_PI / 4, 1e-14);
  EXPECT_NEAR(s.a * s.b, 1, c * c);  // area-preserving at first order
  EXPECT_NEAR(SmallDeformation::tank_treading_rate(L, flow_plane(L)), 0.5, 1e-15);
  EXPECT_TRUE(std::isnan(th.coordinate_taylor(L, t)[0]));
}

TEST(SmallDeformationTheory, RefusesParametersOutsideTheLaw) {
  EXPECT_THROW(SmallDeformation(0, 0.5, 1), std::invalid_argument);
  EXPECT_THROW(SmallDeformation(1, 1.0, 1), std::invalid_argument);
  EXPECT_THROW(SmallDeformation(1, -1.0, 1), std::invalid_argument);
  EXPECT_THROW(SmallDeformation(1, 0.5, 0), std::invalid_argument);
  EXPECT_THROW(SmallDeformation(1, 0.5, std::nan("")), std::invalid_argument);
}
