#pragma once
// 2-D hyperelastic membrane laws W_s(I1, I2) (paper §2.3.3, §2.6), separate from the element.
//
// Invariants of the surface right Cauchy-Green tensor (Barthes-Biesel convention):
//   I1 = lambda1^2 + lambda2^2 - 2 = A^{ab} a_ab - 2,   I2 = J_s^2 - 1 = det(a_ab)/det(A_ab) - 1.
// (The paper's Eq. 21 prints I_s2 = J_s - 1; with that definition Eq. 23 would not reduce to the
//  linear Hooke law Eq. 24, so J_s^2 - 1 is the intended invariant.)
// Laws (G_s surface shear modulus, nu_s surface Poisson ratio, C Skalak area parameter):
//   GH  (Eq. 23): W = G_s/4 (2 I1 - 2 I2 + I1^2/(1 - nu_s))        small strain: G_s, nu_s
//   NH  (Eq. 33): W = G_s/2 (I1 - 1 + 1/(I2 + 1))                  small strain: G_s, nu_s = 1/2
//   SK         : W = G_s/4 (I1^2 + 2 I1 - 2 I2 + C I2^2)            small strain: G_s, nu_s = C/(1+C)
//   MR         : W = G_s/2 [(1-Psi)(I1 - 1 + 1/(I2+1)) + Psi((I1+2)/(I2+1) + I2 - 2)]
//                (thin sheet of incompressible 3-D Mooney-Rivlin, C2/(C1+C2) = Psi;
//                 Psi = 0 is NH)                                    small strain: G_s, nu_s = 1/2
// Second Piola-Kirchhoff tension (contravariant, force per reference length):
//   S^{ab} = dW/dgamma_ab = 2 W1 A^{ab} + 2 W2 J_s^2 a^{ab}   (J_s^2 a^{ab} = adj(a)^{ab}/det A).
// Principal Cauchy tension (force per deformed length): T1 = 2 (l1/l2) W1 + 2 l1 l2 W2.
#include <optional>
#include <string>

namespace capsflow::shell {

enum class LawKind { GeneralizedHooke, NeoHookean, Skalak, MooneyRivlin };

struct MembraneLaw {
  LawKind kind = LawKind::NeoHookean;
  double Gs_ = 1.0;    ///< surface shear modulus G_s
  double nu_ = 0.5;    ///< GH only: surface Poisson ratio
  double C = 1.0;      ///< Skalak: area-dilation parameter; Mooney-Rivlin: Psi in [0, 1]

  /// Energy per reference area, templated so that automatic differentiation can use it.
  template <class S>
  S W_t(const S& I1, const S& I2) const {
    switch (kind) {
      case LawKind::GeneralizedHooke:
        return 0.25 * Gs_ * (2.0 * I1 - 2.0 * I2 + I1 * I1 / (1.0 - nu_));
      case LawKind::NeoHookean:
        return 0.5 * Gs_ * (I1 - 1.0 + 1.0 / (I2 + 1.0));
      case LawKind::MooneyRivlin:
        return 0.5 * Gs_ * ((1.0 - C) * (I1 - 1.0 + 1.0 / (I2 + 1.0)) + C * ((I1 + 2.0) / (I2 + 1.0) + I2 - 2.0));
      case LawKind::Skalak:
      default:
        return 0.25 * Gs_ * (I1 * I1 + 2.0 * I1 - 2.0 * I2 + C * I2 * I2);
    }
  }
  double W(double I1, double I2) const { return W_t<double>(I1, I2); }
  double W1(double I1, double I2) const {  ///< dW/dI1 (inline: called per element)
    switch (kind) {
      case LawKind::GeneralizedHooke: return 0.5 * Gs_ + 0.5 * Gs_ * I1 / (1.0 - nu_);
      case LawKind::NeoHookean: return 0.5 * Gs_;
      case LawKind::MooneyRivlin: return 0.5 * Gs_ * ((1.0 - C) + C / (I2 + 1.0));
      case LawKind::Skalak: default: return 0.5 * Gs_ * (I1 + 1.0);
    }
  }
  double W2(double I1, double I2) const {  ///< dW/dI2
    switch (kind) {
      case LawKind::GeneralizedHooke: return -0.5 * Gs_;
      case LawKind::NeoHookean: { const double j2 = I2 + 1.0; return -0.5 * Gs_ / (j2 * j2); }
      case LawKind::MooneyRivlin: {
        const double j2 = I2 + 1.0;
        return 0.5 * Gs_ * (-(1.0 - C) / (j2 * j2) + C * (1.0 - (I1 + 2.0) / (j2 * j2)));
      }
      case LawKind::Skalak: default: return 0.5 * Gs_ * (C * I2 - 1.0);
    }
  }
  double W11(double I1, double I2) const;
  double W12(double I1, double I2) const;
  double W22(double I1, double I2) const;

  /// 2nd PK tension S^{ab} (symmetric 2x2 as Srr, Sss, Srs) from the reference covariant metric
  /// A = (Arr, Ass, Ars) and the current one a = (arr, ass, ars).
  void tension(const double A[3], const double a[3], double S[3]) const;
  /// Principal Cauchy tensions T1, T2 (per deformed length) for principal stretches l1, l2.
  void principal_tensions(double l1, double l2, double& T1, double& T2) const;

  double Gs() const { return Gs_; }  ///< small-strain surface shear modulus
  double nu_s() const;               ///< small-strain surface Poisson ratio (K_s = G_s (1+nu)/(1-nu))
  const char* name() const;
};

/// The law's short name: "gh" | "nh" | "skalak" | "mr" (the scene and output spelling).
const char* to_string(LawKind kind);
/// The kind named `name` ("sk" is accepted for Skalak), or nothing.
std::optional<LawKind> law_from_name(const std::string& name);

/// nu_s is used by GH only; `parameter` is Skalak's C or Mooney-Rivlin's Psi (unused by GH and NH).
/// Throws std::invalid_argument on parameters outside the law's range.
MembraneLaw make_law(LawKind kind, double Gs, double nu_s = 0.5, double parameter = 1.0);
/// Same, by name; throws std::invalid_argument on an unknown name.
MembraneLaw make_law(const std::string& name, double Gs, double nu_s = 0.5, double parameter = 1.0);

}  // namespace capsflow::shell
