#pragma once
// Mooney–Rivlin membrane: W = G_s/2 [(1 − Ψ)(I1 − 1 + 1/(I2 + 1)) + Ψ((I1 + 2)/(I2 + 1) + I2 − 2)],
// the thin-sheet limit of an incompressible 3-D Mooney–Rivlin solid with Ψ = C2/(C1 + C2)
// (Ψ = 0 is the neo-Hookean law). Small strain: G_s, ν_s = ½.
#include "capsflow/shell/laws/law_kind.hpp"

namespace capsflow::shell {

struct MooneyRivlin {
  static constexpr LawKind kind = LawKind::MooneyRivlin;
  static constexpr const char* name = "mr";
  double Gs = 1.0;   ///< surface shear modulus G_s
  double psi = 0.0;  ///< Ψ in [0, 1]

  /// `parameter` is Ψ; throws std::invalid_argument unless 0 ≤ Ψ ≤ 1 (`nu_s` is unused).
  static MooneyRivlin make(double Gs, double nu_s, double parameter);
  template <class S>
  S W(const S& I1, const S& I2) const {
    return 0.5 * Gs * ((1.0 - psi) * (I1 - 1.0 + 1.0 / (I2 + 1.0)) + psi * ((I1 + 2.0) / (I2 + 1.0) + I2 - 2.0));
  }
  double W1(double, double I2) const { return 0.5 * Gs * ((1.0 - psi) + psi / (I2 + 1.0)); }
  double W2(double I1, double I2) const {
    const double j2 = I2 + 1.0;
    return 0.5 * Gs * (-(1.0 - psi) / (j2 * j2) + psi * (1.0 - (I1 + 2.0) / (j2 * j2)));
  }
  double W11(double, double) const { return 0.0; }
  double W12(double, double I2) const {
    const double j2 = I2 + 1.0;
    return -0.5 * Gs * psi / (j2 * j2);
  }
  double W22(double I1, double I2) const {
    const double j3 = (I2 + 1.0) * (I2 + 1.0) * (I2 + 1.0);
    return Gs * ((1.0 - psi) + psi * (I1 + 2.0)) / j3;
  }
  double nu_s() const { return 0.5; }
};

}  // namespace capsflow::shell
