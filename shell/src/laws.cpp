#include "capsflow/shell/laws.hpp"

#include <stdexcept>

namespace capsflow::shell {

double MembraneLaw::W11(double, double) const {
  switch (kind) {
    case LawKind::GeneralizedHooke: return 0.5 * Gs_ / (1.0 - nu_);
    case LawKind::NeoHookean: return 0.0;
    case LawKind::MooneyRivlin: return 0.0;
    case LawKind::Skalak: default: return 0.5 * Gs_;
  }
}
double MembraneLaw::W12(double, double I2) const {
  if (kind != LawKind::MooneyRivlin) return 0.0;
  const double j2 = I2 + 1.0;
  return -0.5 * Gs_ * C / (j2 * j2);
}
double MembraneLaw::W22(double I1, double I2) const {
  switch (kind) {
    case LawKind::GeneralizedHooke: return 0.0;
    case LawKind::NeoHookean: { const double j2 = I2 + 1.0; return Gs_ / (j2 * j2 * j2); }
    case LawKind::MooneyRivlin: {
      const double j3 = (I2 + 1.0) * (I2 + 1.0) * (I2 + 1.0);
      return Gs_ * ((1.0 - C) + C * (I1 + 2.0)) / j3;
    }
    case LawKind::Skalak: default: return 0.5 * Gs_ * C;
  }
}

void MembraneLaw::tension(const double A[3], const double a[3], double S[3]) const {
  const double detA = A[0] * A[1] - A[2] * A[2];
  const double Brr = A[1] / detA, Bss = A[0] / detA, Brs = -A[2] / detA;
  const double I1 = Brr * a[0] + Bss * a[1] + 2.0 * Brs * a[2] - 2.0;
  const double I2 = (a[0] * a[1] - a[2] * a[2]) / detA - 1.0;
  const double w1 = 2.0 * W1(I1, I2), w2 = 2.0 * W2(I1, I2) / detA;
  S[0] = w1 * Brr + w2 * a[1];
  S[1] = w1 * Bss + w2 * a[0];
  S[2] = w1 * Brs - w2 * a[2];
}

void MembraneLaw::principal_tensions(double l1, double l2, double& T1, double& T2) const {
  const double I1 = l1 * l1 + l2 * l2 - 2.0, I2 = l1 * l1 * l2 * l2 - 1.0;
  const double w1 = W1(I1, I2), w2 = W2(I1, I2);
  T1 = 2.0 * (l1 / l2) * w1 + 2.0 * l1 * l2 * w2;
  T2 = 2.0 * (l2 / l1) * w1 + 2.0 * l1 * l2 * w2;
}

double MembraneLaw::nu_s() const {
  switch (kind) {
    case LawKind::GeneralizedHooke: return nu_;
    case LawKind::NeoHookean: return 0.5;
    case LawKind::MooneyRivlin: return 0.5;
    case LawKind::Skalak: default: return C / (1.0 + C);
  }
}

const char* MembraneLaw::name() const { return to_string(kind); }

const char* to_string(LawKind kind) {
  switch (kind) {
    case LawKind::GeneralizedHooke: return "gh";
    case LawKind::NeoHookean: return "nh";
    case LawKind::MooneyRivlin: return "mr";
    case LawKind::Skalak: default: return "skalak";
  }
}

std::optional<LawKind> law_from_name(const std::string& name) {
  if (name == "gh") return LawKind::GeneralizedHooke;
  if (name == "nh") return LawKind::NeoHookean;
  if (name == "mr") return LawKind::MooneyRivlin;
  if (name == "skalak" || name == "sk") return LawKind::Skalak;
  return std::nullopt;
}

MembraneLaw make_law(LawKind kind, double Gs, double nu_s, double parameter) {
  MembraneLaw law;
  law.Gs_ = Gs;
  law.kind = kind;
  switch (kind) {
    case LawKind::GeneralizedHooke:
      if (!(nu_s < 1.0 && nu_s > -1.0)) throw std::invalid_argument("make_law: gh needs -1 < nu_s < 1");
      law.nu_ = nu_s;
      break;
    case LawKind::NeoHookean:
      law.nu_ = 0.5;
      break;
    case LawKind::MooneyRivlin:
      if (!(parameter >= 0.0 && parameter <= 1.0)) throw std::invalid_argument("make_law: mr needs 0 <= Psi <= 1");
      law.C = parameter;
      break;
    case LawKind::Skalak:
      law.C = parameter;
      break;
  }
  return law;
}

MembraneLaw make_law(const std::string& name, double Gs, double nu_s, double parameter) {
  const std::optional<LawKind> kind = law_from_name(name);
  if (!kind) throw std::invalid_argument("make_law: unknown membrane law '" + name + "' (gh | nh | skalak | mr)");
  return make_law(*kind, Gs, nu_s, parameter);
}

}  // namespace capsflow::shell
