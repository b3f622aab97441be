#pragma once
// Observed order of convergence and Richardson extrapolation from values on meshes whose size h
// halves from one to the next (one mesh.level per step), coarse to fine:
//
//   e1 = f(h) − f(2h),  e2 = f(h/2) − f(h)         (the two finest differences)
//   p  = log2(e1/e2)                                (f = f* + C h^p  ⇒  e1/e2 = 2^p)
//   f* ≈ f(h/2) + e2/(2^p − 1)                       (Richardson)
//
// Read only when the data look asymptotic: differences of one sign and p within
// [kMinSaneOrder, kMaxSaneOrder]. Otherwise the status says why and no order or extrapolated
// value is given: data are never forced into an order. With four or more levels the earlier
// triple gives a second extrapolation, and their spread is the uncertainty of f*.
#include <optional>
#include <string>
#include <vector>

#include "capsflow/core/named_enum.hpp"

namespace capsflow::study {

enum class ConvergenceStatus {
  Asymptotic,    // one sign, p in the sane range: order and extrapolation given
  NonMonotone,   // the differences change sign
  NonAsymptotic, // one sign, but p outside the sane range (diverging, or a crossing)
  RoundOff,      // the differences are at round-off: nothing left to converge
  TooFewLevels,  // fewer than three consecutive levels
};
inline constexpr NameTable<ConvergenceStatus, 5> kConvergenceStatusNames{{{ConvergenceStatus::Asymptotic, "asymptotic"},
                                                                          {ConvergenceStatus::NonMonotone, "non_monotone"},
                                                                          {ConvergenceStatus::NonAsymptotic, "non_asymptotic"},
                                                                          {ConvergenceStatus::RoundOff, "round_off"},
                                                                          {ConvergenceStatus::TooFewLevels, "too_few_levels"}}};
constexpr const auto& name_table(ConvergenceStatus) { return kConvergenceStatusNames; }

// Orders outside this range are not read as an asymptotic rate: below 0.5 the sequence barely
// converges (or diverges, p < 0); above 6 the two differences are far more unequal than any
// discretisation in capsflow (O(h) to O(h³)) explains — typically a difference passing near zero.
inline constexpr double kMinSaneOrder = 0.5, kMaxSaneOrder = 6.0;
// Differences below this fraction of the scale are round-off (diagnostics are sums over the
// mesh: ~1e-14 relative; 1e-12 leaves a margin and is far below any discretisation error). The
// scale is the largest |value|, or `scale` when that is larger: a quantity that is itself a
// small difference of O(1) numbers (volume drift V/V0 − 1 ≈ 1e-15) rounds like its O(1) parts.
inline constexpr double kRoundOffRelative = 1e-12;

// One triple (coarse, medium, fine).
struct TripleEstimate {
  ConvergenceStatus status = ConvergenceStatus::TooFewLevels;
  std::optional<double> order;         // Asymptotic only
  std::optional<double> extrapolated;  // Asymptotic (Richardson) or RoundOff (the fine value)
};
TripleEstimate estimate_triple(double coarse, double medium, double fine, double scale = 0);

struct ConvergenceEstimate {
  ConvergenceStatus status = ConvergenceStatus::TooFewLevels;  // of the three finest levels
  std::optional<double> order, extrapolated;
  // |f*(three finest) − f*(the triple before)| when both triples are asymptotic (four or more
  // levels); for RoundOff the largest finest difference. Else empty, with the reason in `note`.
  std::optional<double> uncertainty;
  std::optional<TripleEstimate> previous;  // the triple before the finest (four or more levels)
  std::vector<std::optional<double>> errors;  // per level: value − extrapolated
  std::string note;  // why an order, an extrapolation or an uncertainty is missing ("" if none is)
};

// `values` per level, coarse to fine, on consecutive levels; `scale` as for kRoundOffRelative.
ConvergenceEstimate estimate_convergence(const std::vector<double>& values, double scale = 0);

}  // namespace capsflow::study
