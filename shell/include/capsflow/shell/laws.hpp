#pragma once
// 2-D hyperelastic membrane laws W_s(I1, I2) (paper §2.3.3, §2.6), separate from the element.
//
// Invariants of the surface right Cauchy-Green tensor (Barthes-Biesel convention):
//   I1 = lambda1^2 + lambda2^2 - 2 = A^{ab} a_ab - 2,   I2 = J_s^2 - 1 = det(a_ab)/det(A_ab) - 1.
// (The paper's Eq. 21 prints I_s2 = J_s - 1; with that definition Eq. 23 would not reduce to the
//  linear Hooke law Eq. 24, so J_s^2 - 1 is the intended invariant.)
// One type per law (laws/membrane_laws.hpp: generalized Hooke, neo-Hookean, Skalak, Mooney-Rivlin),
// each with the same members: its name, make(G_s, nu_s, parameter), W (templated for automatic
// differentiation), W1 = dW/dI1, W2 = dW/dI2, W11, W12, W22 and the small-strain nu_s.
// MembraneLaw holds one of them and forwards to it (std::visit: every law is handled, none is a
// fallback).
// Second Piola-Kirchhoff tension (contravariant, force per reference length):
//   S^{ab} = dW/dgamma_ab = 2 W1 A^{ab} + 2 W2 J_s^2 a^{ab}   (J_s^2 a^{ab} = adj(a)^{ab}/det A).
// Principal Cauchy tension (force per deformed length): T1 = 2 (l1/l2) W1 + 2 l1 l2 W2.
#include <string>
#include <type_traits>
#include <variant>

#include "capsflow/shell/laws/law_kind.hpp"
#include "capsflow/shell/laws/membrane_laws.hpp"

namespace capsflow::shell {

class MembraneLaw {
 public:
  /// The laws, in the order of LawKind.
  using Variant = std::variant<GeneralizedHooke, NeoHookean, Skalak, MooneyRivlin>;

  template <class Law, class = std::enable_if_t<std::is_constructible_v<Variant, Law>>>
  MembraneLaw(const Law& law) : law_(law) {}  // implicit: every law is a MembraneLaw

  LawKind kind() const { return static_cast<LawKind>(law_.index()); }
  const Variant& variant() const { return law_; }

  /// Energy per reference area, templated so that automatic differentiation can use it.
  template <class S>
  S W_t(const S& I1, const S& I2) const {
    return std::visit([&](const auto& l) { return l.template W<S>(I1, I2); }, law_);
  }
  double W(double I1, double I2) const { return W_t<double>(I1, I2); }
  /// dW/dI1 (inline: called per element)
  double W1(double I1, double I2) const {
    return std::visit([&](const auto& l) { return l.W1(I1, I2); }, law_);
  }
  /// dW/dI2
  double W2(double I1, double I2) const {
    return std::visit([&](const auto& l) { return l.W2(I1, I2); }, law_);
  }
  double W11(double I1, double I2) const;
  double W12(double I1, double I2) const;
  double W22(double I1, double I2) const;

  /// 2nd PK tension S^{ab} (symmetric 2x2 as Srr, Sss, Srs) from the reference covariant metric
  /// A = (Arr, Ass, Ars) and the current one a = (arr, ass, ars).
  void tension(const double A[3], const double a[3], double S[3]) const;
  /// Principal Cauchy tensions T1, T2 (per deformed length) for principal stretches l1, l2.
  void principal_tensions(double l1, double l2, double& T1, double& T2) const;

  double Gs() const;    ///< small-strain surface shear modulus
  double nu_s() const;  ///< small-strain surface Poisson ratio (K_s = G_s (1+nu)/(1-nu))
  const char* name() const;

 private:
  Variant law_;
};

/// nu_s is used by GH only; `parameter` is Skalak's C or Mooney-Rivlin's Psi (unused by GH and NH).
/// Throws std::invalid_argument on parameters outside the law's range.
MembraneLaw make_law(LawKind kind, double Gs, double nu_s = 0.5, double parameter = 1.0);
/// Same, by name; throws std::invalid_argument on an unknown name.
MembraneLaw make_law(const std::string& name, double Gs, double nu_s = 0.5, double parameter = 1.0);

}  // namespace capsflow::shell
