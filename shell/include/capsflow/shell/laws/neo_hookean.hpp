#pragma once
// Neo-Hookean membrane (paper Eq. 33): W = G_s/2 (I1 − 1 + 1/(I2 + 1)), the thin-sheet limit of
// an incompressible 3-D neo-Hookean solid. Small strain: G_s, ν_s = ½.
#include "capsflow/shell/laws/law_kind.hpp"

namespace capsflow::shell {

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

}  // namespace capsflow::shell
