// The instability watch on synthetic volume-drift histories: geometric growth above the floor is
// caught at the first step that satisfies the rule; healthy histories (wandering, linear growth,
// growth below the floor or slower than the threshold) never are. Without the volume correction the
// watch judges the drift rate against its running level: a power of t and a changing step pass, a
// geometric mode on top of a physical drift does not.
#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/health/instability_watch.hpp"

using capsflow::InstabilityWatch;

namespace {
// The index of the first sample that the watch reports, −1 if none.
template <class F>
int first_alarm(F drift, int n, InstabilityWatch::Volume volume = InstabilityWatch::Volume::Corrected,
                double dt = 0.01) {
  InstabilityWatch w(volume);
  for (int i = 0; i < n; ++i)
    if (!w.observe(drift(i), dt).empty()) return i;
  return -1;
}
constexpr auto kUncorrected = InstabilityWatch::Volume::Uncorrected;
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

TEST(InstabilityWatch, QuadraticGrowthLooksGeometricAtTheStartWhichIsWhyUncorrectedRunsWatchTheRate) {
  // ((n+1)/n)² ≥ 1.15 for n ≤ 13: an uncorrected run's O(t²) drift would raise it at sample 8.
  EXPECT_EQ(first_alarm([](int i) { return 1e-4 * (i + 1) * (i + 1); }, 200), InstabilityWatch::kSteps);
}

TEST(InstabilityWatch, UncorrectedPhysicalDriftNeverRaisesIt) {
  // O(t²) drift (the case above), large from the start: the rate ∝ t grows ≥ 1.15× per step only in the
  // first six steps, before the watch has its 32-step level.
  EXPECT_EQ(first_alarm([](int i) { return -1e-2 * std::pow(0.01 * i, 2); }, 2000, kUncorrected), -1);
  // A linear drift with a slow oscillation (rate of order 1e-3 per unit time, the measured scale).
  EXPECT_EQ(first_alarm([](int i) { return 1e-3 * 0.01 * i + 1e-4 * std::sin(0.05 * i); }, 2000, kUncorrected), -1);
  // Quiescent: the drift sits at round-off; no 1e-6 of volume moves.
  EXPECT_EQ(first_alarm([](int i) { return 1e-14 * std::pow(1.3, i % 40); }, 400, kUncorrected), -1);
}

TEST(InstabilityWatch, UncorrectedGeometricModeOnAPhysicalDriftIsCaughtEarly) {
  // Background rate 5e-4 per unit time (5e-6 per step of 0.01) plus a mode growing ×1.25 per step from
  // 1e-12 at step 100. The mode's rate passes 10× the background (5e-5 per step) at about step
  // 100 + ln(5e-5/(1e-12·0.25))/ln 1.25 ≈ 185; its ratio to the previous rate passes 1.15 a few steps
  // earlier. Caught within ±5 steps of that, while the mode has moved the volume by < 1e-3.
  auto drift = [](int i) { return -5e-4 * 0.01 * i - (i < 100 ? 0.0 : 1e-12 * std::pow(1.25, i - 100)); };
  const int at = first_alarm(drift, 400, kUncorrected);
  EXPECT_GE(at, 180);  // not before the mode dominates the rate (expected ≈ 185)
  EXPECT_LE(at, 190);
  EXPECT_LT(std::abs(drift(at) - drift(99)), 1e-3);  // the bound on the drift at the stop
}

TEST(InstabilityWatch, UncorrectedWatchDoesNotJudgeAWindowWhoseStepChanges) {
  // The same geometric mode, but the step grows 1.2× per step: the rate could change by that alone.
  InstabilityWatch w(kUncorrected);
  double dt = 1e-6;
  int alarms = 0;
  for (int i = 0; i < 60; ++i, dt *= 1.2) alarms += !w.observe(-1e-9 * std::pow(1.5, i), dt).empty();
  EXPECT_EQ(alarms, 0);
}
