#include "capsflow/core/stepping/rkc_coefficients.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace capsflow {

namespace {
// T_j(w0), T_j'(w0), T_j''(w0) for j = 0..s by the three-term recurrences.
void chebyshev(int s, double w0, std::vector<double>& T, std::vector<double>& dT, std::vector<double>& ddT) {
  T.assign(s + 1, 0.0), dT.assign(s + 1, 0.0), ddT.assign(s + 1, 0.0);
  T[0] = 1, T[1] = w0, dT[1] = 1;
  for (int j = 2; j <= s; ++j) {
    T[j] = 2 * w0 * T[j - 1] - T[j - 2];
    dT[j] = 2 * T[j - 1] + 2 * w0 * dT[j - 1] - dT[j - 2];
    ddT[j] = 4 * dT[j - 1] + 2 * w0 * ddT[j - 1] - ddT[j - 2];
  }
}
}  // namespace

double RkcCoefficients::stability_interval(int s, double damping) {
  if (s < 2) throw std::invalid_argument("RKC: at least 2 stages");
  std::vector<double> T, dT, ddT;
  const double w0 = 1 + damping / (static_cast<double>(s) * s);
  chebyshev(s, w0, T, dT, ddT);
  return (1 + w0) * ddT[s] / dT[s];  // (1 + w0)/w1
}

int RkcCoefficients::stages_for(double tau_rho, double damping) {
  // β(s) ≈ 0.65 s²: start just below the root and step up to the exact bound.
  int s = std::max(2, static_cast<int>(std::sqrt(std::max(0.0, tau_rho) / 0.66)));
  while (s > 2 && stability_interval(s - 1, damping) >= tau_rho) --s;
  while (stability_interval(s, damping) < tau_rho) ++s;
  return s;
}

RkcCoefficients RkcCoefficients::make(int s, double damping) {
  if (s < 2) throw std::invalid_argument("RKC: at least 2 stages");
  RkcCoefficients k;
  k.stages = s;
  k.damping = damping;
  std::vector<double> T, dT, ddT;
  const double w0 = 1 + damping / (static_cast<double>(s) * s);
  chebyshev(s, w0, T, dT, ddT);
  const double w1 = dT[s] / ddT[s];
  k.beta = (1 + w0) / w1;
  std::vector<double> b(s + 1), a(s + 1);
  for (int j = 2; j <= s; ++j) b[j] = ddT[j] / (dT[j] * dT[j]);
  b[0] = b[1] = b[2];
  for (int j = 0; j <= s; ++j) a[j] = 1 - b[j] * T[j];
  k.mu.assign(s + 1, 0.0), k.nu.assign(s + 1, 0.0), k.mu_t.assign(s + 1, 0.0), k.gamma_t.assign(s + 1, 0.0);
  k.mu_t[1] = b[1] * w1;
  for (int j = 2; j <= s; ++j) {
    k.mu[j] = 2 * b[j] * w0 / b[j - 1];
    k.nu[j] = -b[j] / b[j - 2];
    k.mu_t[j] = 2 * b[j] * w1 / b[j - 1];
    k.gamma_t[j] = -a[j - 1] * k.mu_t[j];
  }
  return k;
}

}  // namespace capsflow
