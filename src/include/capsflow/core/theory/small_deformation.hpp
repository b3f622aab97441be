#pragma once
// First-order small-deformation theory of an initially spherical capsule (docs/small-deformation.md):
// a thin membrane with small-strain surface shear modulus G_s and Poisson ratio ν_s, inner/outer
// viscosity ratio λ, in a linear flow v∞ = L x, from the undeformed unit sphere at t = 0, as
// Ca = μγ̇a/G_s → 0 (capsflow units: μ = γ̇ = a = 1, so G_s = 1/Ca_s). An analytic oracle: it uses
// no capsflow numerics, only the closed forms derived in the docs.
//
// The capsule stays, to O(Ca²), the ellipsoid r = 1 + x̂·F(t)·x̂ with F(t) = c(t) E, E = sym(L): every
// shape observable is the amplitude c(t) times a property of E. c(t) = c∞ (1 − w0 e^{−s0 t} − w1 e^{−s1 t})
// with two relaxation rates s0 < s1 of the degree-2 modes (radial and tangential displacement).
#include <array>

#include "capsflow/core/geometry/flow_plane.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow::theory {

using Mat2 = Eigen::Matrix2d;
using Vec2 = Eigen::Vector2d;

// The two degree-2 modes of the sphere, per unit symmetric trace-free tensor T (docs §2):
//   radial     Y_T(x̂) x̂,      Y_T = x̂·T·x̂
//   tangential (I − x̂x̂)·T·x̂
// Viscous traction jump (outer − inner) of a surface velocity A-radial + B-tangential, with the flow
// E x outside: (radial, tangential) coefficients = 5 (1, 1) − R(λ) (A, B) (docs §3).
Mat2 viscous_resistance(double viscosity_ratio);
// Membrane load (on the fluid, per unit area) of the displacement F-radial + H-tangential under the
// linearised 2-D Hooke law: (radial, tangential) coefficients = K (F, H) (docs §2).
Mat2 membrane_stiffness(double shear_modulus, double poisson_ratio);
// The traction coefficient of a rigid sphere in the strain E: 5 μ E·n (both modes).
inline constexpr double kRigidSphereTraction = 5.0;

class SmallDeformation {
 public:
  // Throws std::invalid_argument unless G_s > 0, −1 < ν_s < 1 and λ > 0 (all finite).
  SmallDeformation(double shear_modulus, double poisson_ratio, double viscosity_ratio);

  // The shape amplitude: F(t) = c(t) E. c(0) = 0.
  double amplitude(double t) const;
  double steady_amplitude() const { return c_inf_; }  // (5/2) (2 + ν_s)/((1 + ν_s) G_s), any λ
  double initial_rate() const;                         // dc/dt(0) = 5/(2λ + 3)
  // The decay rates s0 < s1 and weights w0 + w1 = 1 of c(t) = c∞ (1 − Σ w_k e^{−s_k t}).
  const std::array<double, 2>& rates() const { return rates_; }
  const std::array<double, 2>& weights() const { return weights_; }
  // ∫0^∞ (1 − c/c∞) dt = Σ w_k/s_k: the one time scale of the transient (docs §5.3).
  double relaxation_time() const;
  // d(F, H)/dt per unit E at the mode amplitudes y = (F, H): R⁻¹ (5 (1, 1) − K y).
  Vec2 mode_rates(const Vec2& amplitudes) const;

  // The ellipse of the capsule in the flow plane of L (as geometry/flow_plane measures it):
  // a, b = 1 + c e±, D = c (e+ − e−)/2, θ = the direction of E's larger in-plane eigenvalue
  // (45° in simple shear, 0 in planar hyperbolic flow, at every t > 0).
  InPlaneShape in_plane_shape(const Mat3& L, const FlowPlane& plane, double t) const;
  // The membrane's rotation rate in the plane, in the sign of TankTreadingMeter: at first order the
  // membrane turns rigidly with the vorticity, ½ ∇×v∞ · n (1/2 in simple shear).
  static double tank_treading_rate(const Mat3& L, const FlowPlane& plane);
  // D12, D13, D23 of docs/conventions.md §5.3: c (E_ii − E_jj)/2, for a diagonal E only (the
  // inertia axes are then the coordinate axes); NaN otherwise (simple shear: use in_plane_shape).
  Vec3 coordinate_taylor(const Mat3& L, double t) const;

 private:
  double lambda_;
  Mat2 R_, K_;
  double c_inf_;
  std::array<double, 2> rates_{}, weights_{};
};

// The surface velocity of the undeformed sphere at t = 0 (no membrane load: a tensionless drop):
// Ω × x + 5/(2λ + 3) E x, Ω the rotation of L. Exact for the sphere, not only at first order.
Vec3 initial_surface_velocity(const Mat3& L, double viscosity_ratio, const Vec3& x);

}  // namespace capsflow::theory
