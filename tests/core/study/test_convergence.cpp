// Observed order and Richardson extrapolation (study/convergence.hpp) on synthetic sequences
// f(level) = f* + C h^p (+ D h^q), h = 2^-level, whose order and limit are known exactly.
#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/study/convergence.hpp"

using namespace capsflow;
using namespace capsflow::study;

namespace {

std::vector<double> sequence(double limit, double c, double p, int first, int last, double d = 0, double q = 0) {
  std::vector<double> v;
  for (int l = first; l <= last; ++l) {
    const double h = std::ldexp(1.0, -l);
    v.push_back(limit + c * std::pow(h, p) + d * std::pow(h, q));
  }
  return v;
}

}  // namespace

TEST(Convergence, KnownOrderAndLimitAreRecoveredToRoundOff) {
  for (double p : {1.0, 2.0, 3.0, 2.5}) {
    for (double c : {0.7, -3.0}) {
      const double limit = -0.1667;
      const std::vector<double> v = sequence(limit, c, p, 3, 5);
      const ConvergenceEstimate e = estimate_convergence(v);
      ASSERT_EQ(e.status, ConvergenceStatus::Asymptotic) << "p " << p << " c " << c;
      // The differences e1, e2 ~ |C| h^p ≥ 1e-5 carry a rounding of ~ε|f| ≈ 2e-17 each: the order is
      // exact to ~ε|f|/|e2| ≈ 1e-11; the limit, to a few ε|f|.
      EXPECT_NEAR(*e.order, p, 1e-9) << "c " << c;
      EXPECT_NEAR(*e.extrapolated, limit, 1e-14) << "p " << p << " c " << c;
      // Each level's error against the limit is C h^p, to the same rounding.
      for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(*e.errors[static_cast<std::size_t>(i)], c * std::pow(std::ldexp(1.0, -(3 + i)), p), 1e-14);
      EXPECT_FALSE(e.uncertainty);  // three levels: no second triple, and the note says so
      EXPECT_NE(e.note.find("four levels"), std::string::npos) << e.note;
    }
  }
}

TEST(Convergence, FourLevelsGiveAnUncertaintyThatCoversTheHigherOrderTerm) {
  // f = f* + h² + 4 h³: the finest triple's extrapolation is off by O(h³), the earlier one's by
  // ~8× more, so their spread bounds the actual error (the property the uncertainty claims).
  const double limit = 1.25;
  const std::vector<double> v = sequence(limit, 1.0, 2.0, 3, 6, 4.0, 3.0);
  const ConvergenceEstimate e = estimate_convergence(v);
  ASSERT_EQ(e.status, ConvergenceStatus::Asymptotic);
  ASSERT_TRUE(e.uncertainty && e.previous);
  EXPECT_EQ(e.previous->status, ConvergenceStatus::Asymptotic);
  const double actual = std::abs(*e.extrapolated - limit);
  EXPECT_GT(actual, 1e-8);  // the h³ term is really there (≈ 4·2^-18 after extrapolation ~ 1e-5)
  EXPECT_LT(actual, *e.uncertainty);
  EXPECT_LT(*e.uncertainty, 10 * actual);  // and not vacuous: the earlier triple is off by ~8× (see above)
  // Exact data of one order on four levels: both triples agree to rounding.
  const ConvergenceEstimate x = estimate_convergence(sequence(limit, 0.5, 2.0, 3, 6));
  ASSERT_TRUE(x.uncertainty);
  EXPECT_LT(*x.uncertainty, 1e-14);  // two extrapolations of exact data: a few ε|f|
}

TEST(Convergence, DifferencesChangingSignAreNonMonotoneWithoutAnOrder) {
  // 1.0, 1.1, 1.05: e1 = +0.1, e2 = −0.05 (a pre-asymptotic overshoot).
  const ConvergenceEstimate e = estimate_convergence({1.0, 1.1, 1.05});
  EXPECT_EQ(e.status, ConvergenceStatus::NonMonotone);
  EXPECT_FALSE(e.order);
  EXPECT_FALSE(e.extrapolated);
  EXPECT_FALSE(e.uncertainty);
  EXPECT_FALSE(e.errors[2]);
  EXPECT_NE(e.note.find("change sign"), std::string::npos) << e.note;
  // Alternating data from an h-term with a sign flip per level: also non-monotone.
  std::vector<double> alt;
  for (int l = 3; l <= 5; ++l) alt.push_back(2.0 + (l % 2 ? 1 : -1) * std::ldexp(1.0, -2 * l));
  EXPECT_EQ(estimate_convergence(alt).status, ConvergenceStatus::NonMonotone);
}

TEST(Convergence, OrdersOutsideTheSaneRangeAreNonAsymptotic) {
  // Growing differences (p = −1: diverging) and a near-crossing (p = 8).
  for (double p : {-1.0, 0.2, 8.0}) {
    const ConvergenceEstimate e = estimate_convergence(sequence(3.0, 0.4, p, 3, 5));
    EXPECT_EQ(e.status, ConvergenceStatus::NonAsymptotic) << p;
    EXPECT_FALSE(e.order) << p;
    EXPECT_FALSE(e.extrapolated) << p;
    EXPECT_NE(e.note.find("not asymptotic"), std::string::npos) << e.note;
  }
  // Just inside the range is read as an order.
  EXPECT_EQ(estimate_convergence(sequence(3.0, 0.4, 5.5, 3, 5)).status, ConvergenceStatus::Asymptotic);
}

TEST(Convergence, RoundOffAndTooFewLevelsAreSaidSo) {
  const ConvergenceEstimate r = estimate_convergence({0.0, 0.0, 0.0});  // e.g. volume drift at t = 0
  EXPECT_EQ(r.status, ConvergenceStatus::RoundOff);
  EXPECT_FALSE(r.order);
  EXPECT_EQ(*r.extrapolated, 0.0);
  const ConvergenceEstimate s = estimate_convergence({0.5, 0.5 + 1e-15, 0.5});
  EXPECT_EQ(s.status, ConvergenceStatus::RoundOff);
  // Volume drift V/V0 − 1 at round-off on every level (measured 4e-16, 3e-15, 1e-15 on the Fig. 4
  // case): relative to the values themselves these are "differences", relative to the O(1)
  // volumes they come from they are round-off — which the scale says.
  EXPECT_EQ(estimate_convergence({4.4e-16, 3.1e-15, 1.3e-15}).status, ConvergenceStatus::NonMonotone);
  EXPECT_EQ(estimate_convergence({4.4e-16, 3.1e-15, 1.3e-15}, 1.0).status, ConvergenceStatus::RoundOff);
  // ... while a real trend far above round-off keeps its order with that scale.
  EXPECT_EQ(estimate_convergence({-4e-6, -1e-6, -2.5e-7}, 1.0).status, ConvergenceStatus::Asymptotic);
  const ConvergenceEstimate t = estimate_convergence({0.5, 0.6});
  EXPECT_EQ(t.status, ConvergenceStatus::TooFewLevels);
  EXPECT_FALSE(t.order);
  EXPECT_EQ(t.errors.size(), 2u);
  // A zero difference beside a non-zero one has no ratio: never an order.
  EXPECT_EQ(estimate_convergence({0.5, 0.6, 0.6}).status, ConvergenceStatus::NonMonotone);
}

TEST(Convergence, StatusNamesAreTheDocumentedOnes) {
  EXPECT_STREQ(to_string(ConvergenceStatus::Asymptotic), "asymptotic");
  EXPECT_STREQ(to_string(ConvergenceStatus::NonMonotone), "non_monotone");
  EXPECT_STREQ(to_string(ConvergenceStatus::NonAsymptotic), "non_asymptotic");
}
