// The instability watch on synthetic volume-drift histories: geometric growth above the floor is
// caught at the first step that satisfies the rule; healthy histories (wandering, linear growth,
// growth below the floor or slower than the threshold) never are.
#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/dynamics/instability_watch.hpp"

using capsflow::InstabilityWatch;

namespace {
// The index of the first sample that the watch reports, −1 if none.
template <class F>
int first_alarm(F drift, int n) {
  InstabilityWatch w;
  for (int i = 0; i < n; ++i)
    if (!w.observe(drift(i)).empty()) return i;
  return -1;
}
}  // namespace

TEST(InstabilityWatch, GeometricGrowthIsCaughtWhereItCrossesTheFloor) {
  // 1e-7 · 1.2^i passes 1e-6 at i = 13 (1.2^13 = 10.7); every ratio is 1.2 ≥ 1.15: caught exactly there.
  EXPECT_EQ(first_alarm([](int i) { return -1e-7 * std::pow(1.2, i); }, 100), 13);
  // Starting above the floor, it needs kSteps ratios first: sample kSteps.
  EXPECT_EQ(first_alarm([](int i) { return 1e-5 * std::pow(1.3, i); }, 100), InstabilityWatch::kSteps);
}

TEST(InstabilityWatch, HealthyHistoriesNeverRaiseIt) {
  // Slower than the threshold, however large.
  EXPECT_EQ(first_alarm([](int i) { return 1e-5 * std::pow(1.1, i); }, 200), -1);
  // Fast growth that stays below the floor (a healthy run's round-off level).
  EXPECT_EQ(first_alarm([](int i) { return 1e-15 * std::pow(1.3, i); }, 60), -1);  // 1e-15·1.3^59 ≈ 5e-9
  // Linear growth, large from the first step: ratios (n+1)/n fall below 1.15 after six steps.
  EXPECT_EQ(first_alarm([](int i) { return 1e-4 * (i + 1); }, 200), -1);
  // Above the floor but wandering, not growing in every step.
  EXPECT_EQ(first_alarm([](int i) { return 2e-6 * (1.5 + std::sin(1.7 * i)); }, 200), -1);
}

TEST(InstabilityWatch, QuadraticGrowthLooksGeometricAtTheStartWhichIsWhyTheRunUsesItOnlyWithTheCorrection) {
  // ((n+1)/n)² ≥ 1.15 for n ≤ 13: an uncorrected run's O(t²) drift would raise it at sample 8.
  EXPECT_EQ(first_alarm([](int i) { return 1e-4 * (i + 1) * (i + 1); }, 200), InstabilityWatch::kSteps);
}
