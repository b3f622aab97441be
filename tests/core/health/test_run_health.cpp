// The blow-up checks of one step (health/run_health.hpp) on a hand-made two-element sheet, where
// each failure can be made exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "capsflow/core/health/run_health.hpp"

using namespace capsflow;

namespace {
// Two triangles in the plane z = 0: (0,1,2) and (1,3,2), the unit square cut along 1–2.
SurfaceMesh sheet() {
  SurfaceMesh m;
  m.vertices.resize(4, 3);
  m.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0;
  m.triangles.resize(2, 3);
  m.triangles << 0, 1, 2, 1, 3, 2;
  return m;
}
bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }
}  // namespace

TEST(RunHealth, AHealthyStepPasses) {
  const SurfaceMesh m = sheet();
  Points after = m.vertices;
  after(3, 2) = 0.2;  // out of plane, a small bend
  after(0, 0) = -0.1;
  EXPECT_EQ(check_health(m, after, 0.0, blow_up_drift(true)), "");
  // Strong but finite compression of an element (area ratio 1e-3 ≫ kCollapsedAreaRatio) is deformation.
  after = m.vertices;
  after.row(2) << 0, 1e-3, 0;
  EXPECT_EQ(check_health(m, after, 0.0, blow_up_drift(true)), "");
}

TEST(RunHealth, EachFailureIsNamed) {
  const SurfaceMesh m = sheet();
  Points after = m.vertices;
  after(3, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(check_health(m, after, 0.0, blow_up_drift(true)), "non-finite position at node 3");

  after = m.vertices;
  after.row(2) << 0.5, 0, 0;  // on the edge 0–1: element 0 has no area left
  EXPECT_TRUE(starts_with(check_health(m, after, 0.0, blow_up_drift(true)), "element 0 collapsed"))
      << check_health(m, after, 0.0, blow_up_drift(true));

  after = m.vertices;
  after.row(2) << 0.5, -0.5, 0;  // through the edge 0–1: element 0's normal flips
  EXPECT_EQ(check_health(m, after, 0.0, blow_up_drift(true)), "element 0 inverted (its normal flipped in one step)");
}

TEST(RunHealth, VolumeDriftBeyondTheLimitIsARunaway) {
  const SurfaceMesh m = sheet();
  EXPECT_EQ(check_health(m, m.vertices, 0.9e-3, blow_up_drift(true)), "");
  EXPECT_EQ(check_health(m, m.vertices, -0.9e-3, blow_up_drift(true)), "");
  EXPECT_EQ(check_health(m, m.vertices, 2e-3, blow_up_drift(true)), "volume drift 0.002 exceeds 0.001 (runaway)");
  EXPECT_NE(check_health(m, m.vertices, std::nan(""), blow_up_drift(true)), "");  // NaN is not healthy
  // Without the volume correction only 5 % counts (docs/time-integration.md §5.10).
  EXPECT_EQ(check_health(m, m.vertices, 2e-3, blow_up_drift(false)), "");
  EXPECT_NE(check_health(m, m.vertices, 0.06, blow_up_drift(false)), "");
}
