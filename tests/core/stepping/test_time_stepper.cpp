// The schemes behind the TimeStepper seam (stepping/time_stepper.hpp): step control, landing on
// output times, the velocity-at-state bookkeeping and checkpoint round trips, on y' = −λ y.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "capsflow/core/stepping/heun.hpp"
#include "capsflow/core/stepping/rkc2.hpp"

using namespace capsflow;

namespace {
FunctionRhs decay(double lambda) {
  return FunctionRhs([lambda](const Points& y, Points& v) { v = -lambda * y; });
}
Points ones(Eigen::Index n) { return Points::Ones(n, 3); }
}  // namespace

TEST(HeunStepper, AutomaticStepIsTheSafetyTimesTheStableStepAndLandsOnOutputTimes) {
  Heun::Options o;
  o.dt_auto = true;
  o.safety = 0.5;
  o.stable_step = [](const Points&) { return 0.1; };  // the calibrated limit, here a constant
  Heun heun(o);
  FunctionRhs f = decay(1.0);  // ρ = 1: 2/ρ = 2 does not bind
  const Points x = ones(4);
  EXPECT_DOUBLE_EQ(heun.next_step(f, x, {0.0, 1.0, 0}), 0.05);
  EXPECT_EQ(heun.next_step(f, x, {0.98, 0.02, 1}), 0.02);  // shortened to land on the stop, exactly
  // A stiff problem: the measured ρ (× 1.2 margin) binds, 2/(1.2 · 100) < 0.1.
  FunctionRhs stiff = decay(100.0);
  Heun heun2(o);
  EXPECT_NEAR(heun2.next_step(stiff, x, {0.0, 1.0, 0}), 0.5 * 2.0 / (kSpectralRadiusMargin * 100.0), 1e-6);
}

TEST(HeunStepper, IsSecondOrderAndKeepsNoVelocity) {
  Heun::Options o;
  o.dt = 0.1;
  Heun heun(o);
  FunctionRhs f = decay(1.0);
  Points x = ones(2);
  const StepAttempt a = heun.attempt(f, x, 0.1);
  EXPECT_TRUE(a.accepted);
  EXPECT_EQ(a.stages, 2);
  // One Heun step of y' = −y: y = 1 − τ + τ²/2 exactly (the scheme's stability polynomial).
  EXPECT_NEAR(x(0, 0), 1 - 0.1 + 0.005, 1e-15);
  EXPECT_EQ(heun.velocity_at_state(), nullptr);  // its last evaluation is at the predictor
  EXPECT_EQ(heun.next_step(f, x, {0.0, 0.05, 0}), 0.05);  // a fixed step is shortened to land
}

TEST(RkcStepper, ErrorControlledStepsLandInEqualStepsOfAtMostTwentyPercentMore) {
  Rkc2::Options o;
  o.tolerance = 1e-4;
  Rkc2 rkc(o);
  // |F| = 1e-3 √3 per node: the first proposal √(tol/|F|) = 0.24 is capped at 0.1 (StabilizedStepper::proposed_step).
  FunctionRhs f = decay(1e-3);
  const Points x = ones(3);
  EXPECT_DOUBLE_EQ(rkc.next_step(f, x, {0.0, 1.0, 0}), 1.0 / 9);    // 9 steps of 0.111, not 10 of 0.1
  EXPECT_DOUBLE_EQ(rkc.next_step(f, x, {0.0, 0.05, 0}), 0.05);      // shortened to land
  EXPECT_DOUBLE_EQ(rkc.next_step(f, x, {0.0, 0.35, 0}), 0.35 / 3);  // 3 equal steps, not 0.1+0.1+0.1+0.05
  EXPECT_DOUBLE_EQ(rkc.next_step(f, x, {0.0, 0.115, 0}), 0.115);    // one step 15 % longer than proposed
}

TEST(RkcStepper, AFixedStepIsNeverStretched) {
  // time.dt = 0.1 under RKC took 9 steps of 0.111 to an output at 1 (the error-controlled
  // landing above); a fixed step lands by shortening only, as Heun's does.
  Rkc2::Options o;
  o.error_control = false;
  o.fixed_dt = 0.1;
  Rkc2 rkc(o);
  FunctionRhs f = decay(1.0);
  const Points x = ones(3);
  EXPECT_EQ(rkc.next_step(f, x, {0.0, 1.0, 0}), 0.1);
  EXPECT_EQ(rkc.next_step(f, x, {0.0, 0.115, 0}), 0.1);  // then 0.015: never 0.115
  EXPECT_EQ(rkc.next_step(f, x, {0.0, 0.05, 0}), 0.05);  // shortened to land
  Points y = x;
  EXPECT_EQ(rkc.attempt(f, y, 0.1).dt, 0.1);  // taken as given (ρ = 1.2: 2 stages, far below the stage cap)
}

TEST(RkcStepper, VelocityAtStateOnlyAfterAnAcceptedStepAndCheckpointRoundTrip) {
  Rkc2::Options o;
  o.tolerance = 1e-6;
  Rkc2 rkc(o);
  FunctionRhs f = decay(5.0);
  Points x = ones(3);
  EXPECT_EQ(rkc.velocity_at_state(), nullptr);  // nothing evaluated yet
  const double dt = rkc.next_step(f, x, {0.0, 1.0, 0});
  const StepAttempt a = rkc.attempt(f, x, dt);
  ASSERT_TRUE(a.accepted);
  ASSERT_NE(rkc.velocity_at_state(), nullptr);
  EXPECT_LT((*rkc.velocity_at_state() + 5.0 * x).norm(), 1e-12);  // F(y_{n+1}) of this state
  // Save and load into a fresh scheme: the next steps are bit for bit the same.
  nlohmann::json extra = nlohmann::json::object();
  Eigen::MatrixXd m;
  rkc.save(extra, m);
  Rkc2 copy(o);
  copy.load(extra, m, x);
  EXPECT_EQ(copy.velocity_at_state(), nullptr);  // the right-hand side's last evaluation is not this state
  Points x1 = x, x2 = x;
  for (int i = 0; i < 3; ++i) {
    const double d1 = rkc.next_step(f, x1, {0.1 * i, 1.0, 1 + i}), d2 = copy.next_step(f, x2, {0.1 * i, 1.0, 1 + i});
    EXPECT_EQ(d1, d2);
    EXPECT_EQ(rkc.attempt(f, x1, d1).accepted, copy.attempt(f, x2, d2).accepted);
    EXPECT_EQ(x1, x2);
  }
  rkc.forget_state();
  EXPECT_EQ(rkc.velocity_at_state(), nullptr);
}
