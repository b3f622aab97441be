// Stop reasons: summary.json's spellings (users and the study parse them: fixed strings here, as
// documented in docs/scene-and-output.md §3.5), exit codes, and parsing back.
#include <gtest/gtest.h>

#include "capsflow/core/driver/stop_reason.hpp"

using namespace capsflow;

TEST(StopReason, SpellingsAreThoseSummaryJsonHasAlwaysWritten) {
  EXPECT_EQ(StopReason(StopKind::TEnd).to_string(), "t_end");
  EXPECT_EQ(StopReason(StopKind::Steady).to_string(), "steady");
  EXPECT_EQ(StopReason(StopKind::Outlet).to_string(), "outlet");
  EXPECT_EQ(StopReason(StopKind::Interrupted).to_string(), "interrupted");
  EXPECT_EQ(StopReason(StopKind::BlowUp).to_string(), "blow_up");
  EXPECT_EQ(StopReason(StopKind::NoProgress).to_string(), "no_progress");
  EXPECT_EQ(StopReason(StopKind::NoProgress, "51 consecutive rejected steps at t = 1 (last step 1e-05)").to_string(),
            "no_progress: 51 consecutive rejected steps at t = 1 (last step 1e-05)");
  EXPECT_EQ(StopReason(StopKind::SolverFailure, "non-finite velocity at t = 0.5").to_string(),
            "solver_failure: non-finite velocity at t = 0.5");
  EXPECT_EQ(StopReason::health(HealthCondition::NoEquilibrium).to_string(), "no_equilibrium");
  EXPECT_EQ(StopReason::health(HealthCondition::MeshScaleBuckling).name(), "mesh_scale_buckling");
}

TEST(StopReason, ExitCodes) {
  // docs/scene-and-output.md: 0 when the run did what was asked, 3 when its state is not to be
  // trusted (blow-up, solver failure, no progress, a time.stop_on condition), 130 on a signal.
  EXPECT_EQ(StopReason(StopKind::TEnd).exit_code(), 0);
  EXPECT_EQ(StopReason(StopKind::Steady).exit_code(), 0);
  EXPECT_EQ(StopReason(StopKind::Outlet).exit_code(), 0);  // the capsule has passed the channel: done
  EXPECT_EQ(StopReason(StopKind::Interrupted).exit_code(), 130);
  EXPECT_EQ(StopReason(StopKind::BlowUp).exit_code(), 3);
  EXPECT_EQ(StopReason(StopKind::SolverFailure, "x").exit_code(), 3);
  EXPECT_EQ(StopReason(StopKind::NoProgress).exit_code(), 3);
  for (const auto& [c, name] : kHealthConditionNames) EXPECT_EQ(StopReason::health(c).exit_code(), 3) << name;
  EXPECT_TRUE(StopReason(StopKind::Steady).finished());
  EXPECT_FALSE(StopReason(StopKind::Interrupted).finished());
}

TEST(StopReason, ParsesEverySpellingBack) {
  for (const StopKindInfo& i : kStopKinds) {
    if (!i.name) continue;
    const auto r = StopReason::parse(i.name);
    ASSERT_TRUE(r) << i.name;
    EXPECT_EQ(r->kind(), i.kind);
    EXPECT_EQ(r->detail(), "");
  }
  for (const auto& [c, name] : kHealthConditionNames) {
    const auto r = StopReason::parse(name);
    ASSERT_TRUE(r) << name;
    EXPECT_EQ(r->kind(), StopKind::Health);
    EXPECT_EQ(r->condition(), c);
  }
  const auto f = StopReason::parse("solver_failure: rotation Newton did not converge (residual 1.0e-03 rad) at t = 1.18");
  ASSERT_TRUE(f);
  EXPECT_EQ(f->kind(), StopKind::SolverFailure);
  EXPECT_EQ(f->detail(), "rotation Newton did not converge (residual 1.0e-03 rad) at t = 1.18");
  EXPECT_EQ(f->to_string(), "solver_failure: rotation Newton did not converge (residual 1.0e-03 rad) at t = 1.18");
  EXPECT_FALSE(StopReason::parse(""));
  EXPECT_FALSE(StopReason::parse("exploded"));
  EXPECT_FALSE(StopReason::parse("t_end_x"));
}
