#include "capsflow/shell/laws.hpp"

#include <array>
#include <stdexcept>
#include <utility>

namespace capsflow::shell {

namespace {
using Variant = MembraneLaw::Variant;
constexpr std::size_t kLaws = std::variant_size_v<Variant>;

// The alternatives are in the order of LawKind, so that kind() is the variant's index.
template <std::size_t... I>
constexpr bool kinds_in_order(std::index_sequence<I...>) {
  return ((std::variant_alternative_t<I, Variant>::kind == static_cast<LawKind>(I)) && ...);
}
static_assert(kinds_in_order(std::make_index_sequence<kLaws>{}), "MembraneLaw::Variant must follow LawKind");

template <std::size_t... I>
constexpr std::array<const char*, kLaws> law_names(std::index_sequence<I...>) {
  return {std::variant_alternative_t<I, Variant>::name...};
}
constexpr std::array<const char*, kLaws> kNames = law_names(std::make_index_sequence<kLaws>{});

// The law of index k, from its own make() (which checks its parameters).
template <std::size_t I = 0>
MembraneLaw make_alternative(std::size_t k, double Gs, double nu_s, double parameter) {
  using Law = std::variant_alternative_t<I, Variant>;
  if (k == I) return Law::make(Gs, nu_s, parameter);
  if constexpr (I + 1 < kLaws) {
    return make_alternative<I + 1>(k, Gs, nu_s, parameter);
  } else {
    throw std::invalid_argument("make_law: unknown law kind");
  }
}
}  // namespace

GeneralizedHooke GeneralizedHooke::make(double Gs, double nu_s, double) {
  if (!(nu_s < 1.0 && nu_s > -1.0)) throw std::invalid_argument("make_law: gh needs -1 < nu_s < 1");
  return {Gs, nu_s};
}
NeoHookean NeoHookean::make(double Gs, double, double) { return {Gs}; }
Skalak Skalak::make(double Gs, double, double C) { return {Gs, C}; }
MooneyRivlin MooneyRivlin::make(double Gs, double, double psi) {
  if (!(psi >= 0.0 && psi <= 1.0)) throw std::invalid_argument("make_law: mr needs 0 <= Psi <= 1");
  return {Gs, psi};
}

double MembraneLaw::W11(double I1, double I2) const {
  return std::visit([&](const auto& l) { return l.W11(I1, I2); }, law_);
}
double MembraneLaw::W12(double I1, double I2) const {
  return std::visit([&](const auto& l) { return l.W12(I1, I2); }, law_);
}
double MembraneLaw::W22(double I1, double I2) const {
  return std::visit([&](const auto& l) { return l.W22(I1, I2); }, law_);
}
double MembraneLaw::Gs() const {
  return std::visit([](const auto& l) { return l.Gs; }, law_);
}
double MembraneLaw::nu_s() const {
  return std::visit([](const auto& l) { return l.nu_s(); }, law_);
}
const char* MembraneLaw::name() const { return to_string(kind()); }

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

const char* to_string(LawKind kind) {
  const auto k = static_cast<std::size_t>(kind);
  if (k >= kLaws) throw std::invalid_argument("to_string: unknown law kind");
  return kNames[k];
}

std::optional<LawKind> law_from_name(const std::string& name) {
  if (name == "sk") return LawKind::Skalak;  // accepted alias
  for (std::size_t k = 0; k < kLaws; ++k)
    if (name == kNames[k]) return static_cast<LawKind>(k);
  return std::nullopt;
}

MembraneLaw make_law(LawKind kind, double Gs, double nu_s, double parameter) {
  return make_alternative(static_cast<std::size_t>(kind), Gs, nu_s, parameter);
}

MembraneLaw make_law(const std::string& name, double Gs, double nu_s, double parameter) {
  const std::optional<LawKind> kind = law_from_name(name);
  if (!kind) throw std::invalid_argument("make_law: unknown membrane law '" + name + "' (gh | nh | skalak | mr)");
  return make_law(*kind, Gs, nu_s, parameter);
}

}  // namespace capsflow::shell
