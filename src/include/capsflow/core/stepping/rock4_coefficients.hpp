#pragma once
// Coefficients of a fourth-order stabilised Runge–Kutta method of the ROCK4 family (Abdulle 2002,
// "Fourth order Chebyshev methods with recurrence relation"), computed for capsflow by
// scripts/rock4_coefficients.py (docs/time-integration.md §5.8 says how and what was checked).
//
// Its stability polynomial of degree s is R_s(z) = w4(z) P_{s−4}(z): w4 has two pairs of complex
// zeros, P_{s−4} is the orthogonal polynomial for the weight w4(z)²/√(1 − x²) on the interval
// z = L (x − 1)/2, x ∈ [−1, 1], normalised P_j(0) = 1; the zeros make R_s = e^z + O(z⁵), L is the
// longest interval with |R_s| ≤ 1 on [−L, 0] and ℓ_s that interval measured on the step's own
// polynomial (≈ 0.353 s² for large s; equal to L but for s = 117 and 119, whose finishing methods
// exceed 1 by 8e-9 and 6e-9 at z ≈ −8.4: their ℓ_s is 8.39, so stages_for never picks them).
// A step of size τ from y_n:
//   g_0 = y_n,  g_1 = g_0 + μ_1 τ F(g_0),
//   g_j = μ_j τ F(g_{j−1}) − ν_j g_{j−1} − κ_j g_{j−2},  j = 2..s−4   (−ν_j − κ_j = 1),
// then the four-stage finishing method W from u_1 = g_{s−4}: u_i = u_1 + τ Σ_{k<i} a_ik F(u_k),
// y_{n+1} = u_1 + τ Σ b_i F(u_i); W's coefficients give the composition order 4 for nonlinear
// problems (the eight order conditions of the composite tableau). The embedded third-order result
// ŷ = u_1 + τ (Σ b̂_i F(u_i) + b̂_5 F(y_{n+1})) gives the error estimate y_{n+1} − ŷ, whose leading
// linear term is z⁴/24 (that of Kutta's third-order method).
//
// The table holds, per s, ℓ_s, L, the zeros of w4 and W's and the embedded weights; μ, ν, κ follow
// from the zeros by the discretised Stieltjes procedure (exact: Gauss–Chebyshev quadrature of
// degree above 2s).
#include <array>
#include <vector>

namespace capsflow {

struct Rock4Coefficients {
  int stages = 0;
  double interval = 0;  // ℓ_s: |R_s(z)| ≤ 1 on [−ℓ_s, 0]
  // Recurrence, index j = 1..s−4 (entry 0 unused).
  std::vector<double> mu, nu, kappa;
  // Finishing method: a21, a31, a32, a41, a42, a43; b1..b4; embedded b̂1..b̂5.
  std::array<double, 6> a{};
  std::array<double, 4> b{};
  std::array<double, 5> bhat{};

  static constexpr int kMinStages = 5;
  static int max_stages();
  static Rock4Coefficients make(int stages);
  // The fewest stages s ≥ 5 with ℓ_s ≥ tau_rho; max_stages() if none.
  static int stages_for(double tau_rho);
  static double stability_interval(int stages);
  // R_s(z) by the recurrence and W (for tests: the table against its stated properties).
  double stability_polynomial(double z) const;
};

}  // namespace capsflow
