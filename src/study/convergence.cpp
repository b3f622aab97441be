#include "capsflow/core/study/convergence.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace capsflow::study {

TripleEstimate estimate_triple(double coarse, double medium, double fine, double scale) {
  TripleEstimate t;
  const double e1 = medium - coarse, e2 = fine - medium;
  const double round_off = kRoundOffRelative * std::max({std::abs(coarse), std::abs(medium), std::abs(fine), scale});
  if (std::abs(e1) <= round_off && std::abs(e2) <= round_off) {
    t.status = ConvergenceStatus::RoundOff;
    t.extrapolated = fine;
    return t;
  }
  if ((e1 < 0) != (e2 < 0) || e1 == 0 || e2 == 0) {  // a zero difference next to a non-zero one: no ratio
    t.status = ConvergenceStatus::NonMonotone;
    return t;
  }
  const double p = std::log2(e1 / e2);
  if (!(p >= kMinSaneOrder && p <= kMaxSaneOrder)) {
    t.status = ConvergenceStatus::NonAsymptotic;
    return t;
  }
  t.status = ConvergenceStatus::Asymptotic;
  t.order = p;
  t.extrapolated = fine + e2 / (std::exp2(p) - 1);
  return t;
}

namespace {
std::string describe(const TripleEstimate& t, std::size_t first, std::size_t n) {
  return fmt::format("levels {}–{} of {}: {}", first + 1, first + 3, n, to_string(t.status));
}
}  // namespace

ConvergenceEstimate estimate_convergence(const std::vector<double>& values, double scale) {
  ConvergenceEstimate c;
  const std::size_t n = values.size();
  c.errors.assign(n, std::nullopt);
  if (n < 3) {
    c.note = fmt::format("{} level{}: an order needs three", n, n == 1 ? "" : "s");
    return c;
  }
  const TripleEstimate last = estimate_triple(values[n - 3], values[n - 2], values[n - 1], scale);
  c.status = last.status;
  c.order = last.order;
  c.extrapolated = last.extrapolated;
  if (n >= 4) c.previous = estimate_triple(values[n - 4], values[n - 3], values[n - 2], scale);
  if (c.extrapolated)
    for (std::size_t i = 0; i < n; ++i) c.errors[i] = values[i] - *c.extrapolated;
  switch (last.status) {
    case ConvergenceStatus::Asymptotic:
      if (!c.previous)
        c.note = "uncertainty needs four levels (the spread of two triples' extrapolations)";
      else if (c.previous->status == ConvergenceStatus::Asymptotic)
        c.uncertainty = std::abs(*c.extrapolated - *c.previous->extrapolated);
      else
        c.note = "no uncertainty: " + describe(*c.previous, n - 4, n);
      break;
    case ConvergenceStatus::RoundOff:
      c.uncertainty = std::max(std::abs(values[n - 1] - values[n - 2]), std::abs(values[n - 2] - values[n - 3]));
      c.note = "differences at round-off: no order";
      break;
    case ConvergenceStatus::NonMonotone:
      c.note = "the differences between levels change sign: no order";
      break;
    case ConvergenceStatus::NonAsymptotic:
      c.note = fmt::format("observed order log2(e1/e2) = {:.3g} outside [{:g}, {:g}]: not asymptotic",
                           std::log2((values[n - 2] - values[n - 3]) / (values[n - 1] - values[n - 2])), kMinSaneOrder,
                           kMaxSaneOrder);
      break;
    case ConvergenceStatus::TooFewLevels:
      break;
  }
  return c;
}

}  // namespace capsflow::study
