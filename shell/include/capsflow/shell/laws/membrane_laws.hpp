#pragma once
// The membrane laws W_s(I1, I2), one type each (laws.hpp: invariants, tension, MembraneLaw).
// Every law has the same members: kind, make(G_s, nu_s, parameter) (which checks the law's range),
// W (templated for automatic differentiation), W1 = dW/dI1, W2 = dW/dI2, W11, W12, W22, nu_s
// (the small-strain Poisson ratio), and its scene name.
#include "capsflow/shell/laws/law_kind.hpp"

namespace capsflow::shell {

// Generalized Hooke law (paper Eq. 23): W = G_s/4 (2 I1 − 2 I2 + I1²/(1 − ν_s)).
// Small strain: shear modulus G_s, Poisson ratio ν_s (−1 < ν_s < 1).
struct GeneralizedHooke {
  static constexpr LawKind kind = LawKind::GeneralizedHooke;
  static constexpr const char* name = "gh";
  double Gs = 1.0;  ///< surface shear modulus G_s
  double nu = 0.5;  ///< surface Poisson ratio ν_s

  /// Throws std::invalid_argument unless −1 < ν_s < 1 (`parameter` is unused).
  static GeneralizedHooke make(double Gs, double nu_s, double parameter);
  template <class S>
  S W(const S& I1, const S& I2) const {
    return 0.25 * Gs * (2.0 * I1 - 2.0 * I2 + I1 * I1 / (1.0 - nu));
  }
  double W1(double I1, double) const { return 0.5 * Gs + 0.5 * Gs * I1 / (1.0 - nu); }
  double W2(double, double) const { return -0.5 * Gs; }
  double W11(double, double) const { return 0.5 * Gs / (1.0 - nu); }
  double W12(double, double) const { return 0.0; }
  double W22(double, double) const { return 0.0; }
  double nu_s() const { return nu; }
};

// Neo-Hookean membrane (paper Eq. 33): W = G_s/2 (I1 − 1 + 1/(I2 + 1)), the thin-sheet limit of
// an incompressible 3-D neo-Hookean solid. Small strain: G_s, ν_s = ½.
struct NeoHookean {
  static constexpr LawKind kind = LawKind::NeoHookean;
  static constexpr const char* name = "nh";
  double Gs = 1.0;  ///< surface shear modulus G_s

  /// `nu_s` and `parameter` are unused (ν_s = ½ follows from incompressibility).
  static NeoHookean make(double Gs, double nu_s, double parameter);
  template <class S>
  S W(const S& I1, const S& I2) const {
    return 0.5 * Gs * (I1 - 1.0 + 1.0 / (I2 + 1.0));
  }
  double W1(double, double) const { return 0.5 * Gs; }
  double W2(double, double I2) const {
    const double j2 = I2 + 1.0;
    return -0.5 * Gs / (j2 * j2);
  }
  double W11(double, double) const { return 0.0; }
  double W12(double, double) const { return 0.0; }
  double W22(double, double I2) const {
    const double j2 = I2 + 1.0;
    return Gs / (j2 * j2 * j2);
  }
  double nu_s() const { return 0.5; }
};

// Skalak law (red-cell membranes): W = G_s/4 (I1² + 2 I1 − 2 I2 + C I2²), C the area-dilation
// parameter. Small strain: G_s, ν_s = C/(1 + C).
struct Skalak {
  static constexpr LawKind kind = LawKind::Skalak;
  static constexpr const char* name = "skalak";
  double Gs = 1.0;  ///< surface shear modulus G_s
  double C = 1.0;   ///< area-dilation parameter

  /// `parameter` is C (`nu_s` is unused).
  static Skalak make(double Gs, double nu_s, double parameter);
  template <class S>
  S W(const S& I1, const S& I2) const {
    return 0.25 * Gs * (I1 * I1 + 2.0 * I1 - 2.0 * I2 + C * I2 * I2);
  }
  double W1(double I1, double) const { return 0.5 * Gs * (I1 + 1.0); }
  double W2(double, double I2) const { return 0.5 * Gs * (C * I2 - 1.0); }
  double W11(double, double) const { return 0.5 * Gs; }
  double W12(double, double) const { return 0.0; }
  double W22(double, double) const { return 0.5 * Gs * C; }
  double nu_s() const { return C / (1.0 + C); }
};

// Mooney–Rivlin membrane: W = G_s/2 [(1 − Ψ)(I1 − 1 + 1/(I2 + 1)) + Ψ((I1 + 2)/(I2 + 1) + I2 − 2)],
// the thin-sheet limit of an incompressible 3-D Mooney–Rivlin solid with Ψ = C2/(C1 + C2)
// (Ψ = 0 is the neo-Hookean law). Small strain: G_s, ν_s = ½.
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
