#pragma once
// Skalak law (red-cell membranes): W = G_s/4 (I1² + 2 I1 − 2 I2 + C I2²), C the area-dilation
// parameter. Small strain: G_s, ν_s = C/(1 + C).
#include "capsflow/shell/laws/law_kind.hpp"

namespace capsflow::shell {

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

}  // namespace capsflow::shell
