#pragma once
// Generalized Hooke law (paper Eq. 23): W = G_s/4 (2 I1 − 2 I2 + I1²/(1 − ν_s)).
// Small strain: shear modulus G_s, Poisson ratio ν_s (−1 < ν_s < 1).
#include "capsflow/shell/laws/law_kind.hpp"

namespace capsflow::shell {

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

}  // namespace capsflow::shell
