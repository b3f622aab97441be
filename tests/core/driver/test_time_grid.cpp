// Time bookkeeping of the run loop: tolerances relative to the step, O(1) index updates,
// progress, and the step count `capsflow info` reports.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "capsflow/core/driver/time_grid.hpp"

using namespace capsflow;

TEST(TimeGrid, LandingSnapsOnlyWithinAFractionOfTheStep) {
  // A step shortened to reach t_out lands there exactly despite rounding.
  const double t = 0.30000000000000004, t_out = 0.4;
  EXPECT_EQ(advance_time(t, t_out - t, t_out), t_out);
  // At t_end = 1e10 the old tolerance 1e-12·t_end = 0.01 snapped a step of 1e-3 that ended 5e-3
  // before the output time onto it (a silent jump of five steps). Now it is kept.
  EXPECT_EQ(advance_time(0.094, 1e-3, 0.1), 0.094 + 1e-3);
  EXPECT_FALSE(time_reached(0.095, 0.1, 1e-3));
  EXPECT_TRUE(time_reached(0.1 - 1e-13, 0.1, 1e-3));  // 1e-13 < 1e-9·dt: the same time
  // Large times: 4 ulps of t are allowed for the rounding of t + dt itself.
  const double big = 1e10;
  EXPECT_EQ(advance_time(big - 1e-3, 1e-3, big), big);
}

TEST(TimeGrid, NextIndexIsComputedNotCounted) {
  // t_end = 1e308 once made `while (k·every <= t + 1e-12·t_end) ++k` spin for ever.
  EXPECT_EQ(next_index_after(0.5, 0.5, 1, 1e-3), 2);
  EXPECT_EQ(next_index_after(0.5 - 1e-14, 0.5, 1, 1e-3), 2);  // reached within the tolerance
  EXPECT_EQ(next_index_after(1.26, 0.5, 1, 1e-3), 3);         // skipped intervals are skipped, not replayed
  EXPECT_EQ(next_index_after(0.1, 0.5, 4, 1e-3), 5);          // never backwards
  const std::int64_t k = next_index_after(1e300, 0.5, 1, 1e-3);
  EXPECT_GT(k, 1);
  EXPECT_LT(k, std::numeric_limits<std::int64_t>::max() / 2);  // saturates, no overflow
  EXPECT_EQ(first_index_after(0.3, 0.25), 2);
  EXPECT_EQ(first_index_after(0.0, 0.1), 1);
  EXPECT_EQ(first_index_after(0.5, 0.25), 3);  // an event exactly at t already happened
}

TEST(TimeGrid, AStepThatCannotAdvanceTIsNoProgress) {
  EXPECT_TRUE(step_makes_progress(0, 1e-3));
  EXPECT_FALSE(step_makes_progress(0, 0));        // flow cap 0.02/|L| with |L| = inf (gradient 1e300)
  EXPECT_FALSE(step_makes_progress(0, NAN));
  EXPECT_FALSE(step_makes_progress(0, -1e-3));
  EXPECT_FALSE(step_makes_progress(1e17, 1e-3));  // t + dt rounds back to t
}

TEST(TimeGrid, StepCountIncludesTheStepsOutputTimesForce) {
  // dt = 0.03 and outputs every 0.1: each interval takes 4 steps (3 full, 1 partial), 40 to
  // t_end = 1, where t_end/dt alone says 34.
  EXPECT_EQ(estimated_steps(1.0, 0.1, 0.03), 40);
  // Outputs every 1e-4 with dt = 1e-2: one step per output, 10 000, not 100.
  EXPECT_EQ(estimated_steps(1.0, 1e-4, 1e-2), 10000);
  EXPECT_EQ(estimated_steps(1.0, 0.1, 0.01), 100);  // every/dt = 10 up to rounding: not 11 per interval
  EXPECT_EQ(estimated_steps(2.0, 5.0, 0.1), 20);    // one output interval beyond t_end
  EXPECT_EQ(estimated_steps(1.05, 0.1, 0.05), 21);  // a last partial interval of 0.05
}
