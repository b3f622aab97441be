#pragma once
// Coefficients of the damped second-order Runge–Kutta–Chebyshev method RKC2 (van der Houwen &
// Sommeijer 1980; Sommeijer, Shampine & Verwer 1998, "RKC: an explicit solver for parabolic
// PDEs"; docs/time-integration.md §5.6). With T_j the Chebyshev polynomials of the first kind,
// damping ε, w0 = 1 + ε/s², w1 = T_s'(w0)/T_s''(w0), b_j = T_j''(w0)/T_j'(w0)² (j ≥ 2),
// b_0 = b_1 = b_2, a_j = 1 − b_j T_j(w0):
//   Y_0 = y_n,  Y_1 = Y_0 + μ̃_1 τ F(Y_0),  μ̃_1 = b_1 w1,
//   Y_j = (1 − μ_j − ν_j) Y_0 + μ_j Y_{j−1} + ν_j Y_{j−2} + μ̃_j τ F(Y_{j−1}) + γ̃_j τ F(Y_0),
//   μ_j = 2 b_j w0 / b_{j−1},  ν_j = −b_j / b_{j−2},  μ̃_j = 2 b_j w1 / b_{j−1},  γ̃_j = −a_{j−1} μ̃_j,
//   y_{n+1} = Y_s.
// Its stability polynomial is a_s + b_s T_s(w0 + w1 z): |R(z)| ≤ 1 − O(ε) on the real interval
// [−β(s), 0] with β(s) = (1 + w0)/w1 ≈ 0.65 s² for ε = 2/13 (Heun: 2).
#include <vector>

namespace capsflow {

struct RkcCoefficients {
  int stages = 0;
  double damping = 0;
  double beta = 0;  // real stability interval [−beta, 0] of τλ
  // Index j = 0..stages; entries 0 (and 1 for mu, nu, gamma_t) are unused.
  std::vector<double> mu, nu, mu_t, gamma_t;

  // RKC's damping 2/13: β(s) stays within 1 % of 0.653 s² and the polynomial damps by ≥ 0.95.
  static constexpr double kDefaultDamping = 2.0 / 13.0;
  static RkcCoefficients make(int stages, double damping = kDefaultDamping);
  // The smallest s ≥ 2 with β(s) ≥ tau_rho (τ times the spectral radius, margins included).
  static int stages_for(double tau_rho, double damping = kDefaultDamping);
  static double stability_interval(int stages, double damping = kDefaultDamping);
};

}  // namespace capsflow
