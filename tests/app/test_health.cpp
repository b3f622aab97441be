// Health monitors and honest stop reasons end to end (docs/health-monitors.md): mesh-scale
// buckling of a membrane is flagged before it moves D13, a wall with bending stiffness is not
// flagged, a failed rotation solve and a too-large fixed step stop cleanly, and the safety factor
// is limited to what was measured stable.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "capsflow/core/stepping/stability.hpp"
#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/io/checkpoint.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "run_capsflow.hpp"

namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) { return capsflow_test::scratch("health", name); }
using capsflow_test::run;
using capsflow_test::slurp;
using capsflow_test::summary;
auto series(const fs::path& dir) { return capsflow_test::series_rows(dir); }

// Linear interpolation of column `key` at time t.
double at(const std::vector<std::map<std::string, double>>& s, double t, const std::string& key) {
  for (size_t i = 0; i + 1 < s.size(); ++i) {
    const double ta = s[i].at("t"), tb = s[i + 1].at("t");
    if (ta <= t && t <= tb) return s[i].at(key) + (s[i + 1].at(key) - s[i].at(key)) * (t - ta) / (tb - ta);
  }
  return NAN;
}

void clean(const fs::path& p) { capsflow_test::remove_run(p); }
// The over-stepped case of the blow-up tests: 320-element NH membrane at Ca_s = 0.05 (its --set
// options), and Heun's stability estimate for it. Heun named: RKC's stages follow the stiffness,
// so a fixed step above Heun's estimate is stable there.
const std::string kOverStepped =
    "--set mesh.level=2 --set wall.model=membrane --set wall.law=nh --set flow.ca_s=0.05 --set time.scheme=heun ";
double over_stepped_estimate() {
  const capsflow::Scene sc = capsflow::parse_scene(capsflow::default_scene_toml(), "test",
                                                   {"mesh.level=2", "wall.model=membrane", "wall.law=nh", "flow.ca_s=0.05"});
  return capsflow::stability_estimate(sc, capsflow::min_edge_length(capsflow::make_reference_mesh(sc.mesh))).limit();
}

}  // namespace

// The case: a spherical NH capsule (5120 elements) in planar hyperbolic flow at Ca_s =
// 0.005. A membrane is compressed near the x3 poles and buckles at the mesh scale from γ̇t ≈ 0.12,
// after which its D13 climbs away from the smooth solution; a GSMB wall (α = 3 %) stays smooth.
// The smooth reference is the GSMB run (bending changes D13 by < 0.5 % here: 0.020779 against the
// membrane's 0.020767 at γ̇t = 0.12, measured 2026-11-30).
TEST(Health, MembraneBucklingIsFlaggedBeforeD13LeavesTheSmoothSolutionAndAShellIsNot) {
  const std::string base =
      "--set mesh.shape=sphere --set mesh.level=4 --set flow.type=planar_hyperbolic --set flow.ca_s=0.005 "
      "--set wall.law=nh --set time.scheme=rkc --set output.every=0.02 --set output.checkpoint_every=0 ";
  const fs::path mem = scratch("membrane"), shell = scratch("gsmb");
  EXPECT_EQ(run(base + "--set wall.model=membrane --set time.t_end=0.4 --set 'time.stop_on=[\"mesh_scale_buckling\"]'", mem), 3)
      << slurp(mem.string() + ".log");  // exit 3: a stop_on condition
  ASSERT_EQ(run(base + "--set wall.model=gsmb --set wall.thickness=0.03 --set time.t_end=0.2", shell), 0);
  const auto m = summary(mem), g = summary(shell);
  EXPECT_EQ(m.at("stop_reason"), "mesh_scale_buckling");
  const double t_flag = m.at("t");
  // Not a false alarm on the smooth early response (the facets stay within 1° of the sphere's
  // until γ̇t ≈ 0.1 in this run), and before the end of the run.
  EXPECT_GT(t_flag, 0.1);
  EXPECT_LT(t_flag, 0.2);
  ASSERT_EQ(m.at("health").at("warnings").size(), 1u);
  const std::string msg = m.at("health").at("warnings")[0].at("message");
  EXPECT_NE(msg.find("compression"), std::string::npos) << msg;    // names the cause,
  EXPECT_NE(msg.find("wall.model = \"gsmb\""), std::string::npos);  // the remedy,
  EXPECT_NE(msg.find("since γ̇t"), std::string::npos);             // and the time
  // Up to and at the flag, D13 is within 2 % of the smooth solution (the criterion).
  const auto sm = series(mem), sg = series(shell);
  for (const auto& row : sm) {
    const double ref = at(sg, row.at("t"), "D13");
    if (row.at("t") < 0.02 || !std::isfinite(ref)) continue;  // t = 0: D13 of the sphere is 0/0-like
    EXPECT_LT(std::abs(row.at("D13") / ref - 1), 0.02) << "t = " << row.at("t");
  }
  // The shell: no warning, and its grid-scale oscillation stays at the smooth mesh's level.
  EXPECT_TRUE(g.at("health").at("warnings").empty()) << g.at("health").dump();
  EXPECT_LT(g.at("health").at("grid_oscillation_max").get<double>(), 0.01);  // measured 0.0024; threshold 0.03
  clean(mem), clean(shell);
}

TEST(Health, AFailedRotationSolveStopsWithItsReasonAndAReadableFolder) {
  const fs::path out = scratch("newton");
  // One Newton iteration cannot bring the rotations to equilibrium after the first stage. A fixed
  // step: with error control the step would be retried shorter (TimeSchemes.AStageWhoseRotation-
  // SolveFailsIsRetriedInAShorterStep), and with 1 iteration the run then limps on in short steps.
  const int code = run("--set mesh.level=2 --set wall.max_newton=1 --set time.t_end=0.2 --set time.dt=0.004", out);
  EXPECT_EQ(code, 3) << slurp(out.string() + ".log");
  const auto s = summary(out);
  EXPECT_EQ(s.at("stop_reason").get<std::string>().rfind("solver_failure: rotation Newton", 0), 0u) << s.at("stop_reason");
  EXPECT_EQ(slurp(out / "timeseries.csv").find("nan"), std::string::npos);  // never NaN in an output file
  EXPECT_NO_THROW(capsflow::io::read_checkpoint(out / "checkpoint.h5"));    // the last healthy state
  clean(out);
}

// An inner solve that fails at an output row between steps (dense output evaluates the wall, and at
// λ ≠ 1 the second-kind solve, at the interpolated state) ends the run like any solver failure:
// exit 3, summary.json with its reason, the rows written before it and a readable checkpoint. Before,
// the failure escaped the run loop: exit 1, no summary, and a CSV that stopped at t = 0 although the
// run had reached γ̇t = 1.3 (the rotation Newton capped at 3 iterations) and 0.27 (GMRES capped at 3).
TEST(Health, ASolveThatFailsAtAnOutputRowStopsTheRunCleanly) {
  const std::vector<std::pair<std::string, std::string>> cases{
      {"--set mesh.level=3 --set time.t_end=5 --set wall.max_newton=3", "solver_failure: rotation Newton"},
      {std::string(CAPSFLOW_SOURCE_DIR) + "/scenes/sphere_shear_lambda5.toml --set mesh.level=2 --set time.t_end=3 "
           "--set fluid.max_gmres=3",
       "solver_failure: viscosity-ratio GMRES"}};
  for (const auto& [args, reason] : cases) {
    const fs::path out = scratch("output-row-failure");
    EXPECT_EQ(run(args, out), 3) << args << "\n" << slurp(out.string() + ".log");
    const auto s = summary(out);
    EXPECT_EQ(s.at("stop_reason").get<std::string>().rfind(reason, 0), 0u) << s.at("stop_reason");
    EXPECT_GT(s.at("t").get<double>(), 0.0);  // the run had advanced
    const auto rows = series(out);
    ASSERT_GE(rows.size(), 2u) << args;  // the start and the rows written before the failure
    EXPECT_LE(rows.back().at("t"), s.at("t").get<double>() + 1e-12);  // none beyond the state kept
    EXPECT_NO_THROW(capsflow::io::read_checkpoint(out / "checkpoint.h5"));
    EXPECT_EQ(capsflow::io::read_checkpoint(out / "checkpoint.h5").t, s.at("t").get<double>());  // the state kept
    clean(out);
  }
}

TEST(Health, RotationsAreSolvedPastASaddleInAFoldedShell) {
  // Found by the stress campaign (2026-11-30): GSMB NH sphere, Ca_s = 1, planar hyperbolic flow,
  // 1280 elements. At γ̇t = 1.18 the folded wall makes the rotation equilibrium a saddle; the Newton
  // iteration needs 45–47 steps to leave it (docs/shell.md §2.4), and the run stopped with
  // solver_failure at the former cap of 20. With that cap Heun still fails there (γ̇t = 1.13: the
  // check that this test can fail); RKC now gets past it too, by retrying the failed step shorter.
  const std::string scene = "--set mesh.level=3 --set mesh.shape=sphere --set wall.law=nh --set flow.ca_s=1 "
                            "--set flow.type=planar_hyperbolic --set time.scheme=rkc --set time.t_end=1.3 ";
  const fs::path out = scratch("saddle");
  EXPECT_EQ(run(scene, out), 0) << slurp(out.string() + ".log");
  EXPECT_EQ(summary(out).at("stop_reason"), "t_end");
  clean(out);
  const fs::path capped = scratch("saddle-capped");
  EXPECT_EQ(run(scene + "--set wall.max_newton=20 --set time.scheme=heun", capped), 3) << slurp(capped.string() + ".log");
  EXPECT_EQ(summary(capped).at("stop_reason").get<std::string>().rfind("solver_failure: rotation Newton", 0), 0u);
  clean(capped);
}

TEST(Health, RotationsConvergeWhereTheFoldedShellIsSoft) {
  // Found by the stress campaign (2026-11-30): GSMB Skalak C = 10 sphere, Ca_s = 10, simple shear, 1280
  // elements, past its folds. With the geometric term of the tangent floored at −½ of the material
  // diagonal, Newton converged linearly at 0.87 per step near γ̇t = 8 and the run stopped with
  // solver_failure at 8.03 even with 100 steps allowed; with the floor at −0.9 it needs ≤ 21.
  const fs::path out = scratch("soft");
  EXPECT_EQ(run("--set mesh.level=3 --set mesh.shape=sphere --set wall.law=skalak --set wall.skalak_c=10 "
                "--set flow.ca_s=10 --set flow.type=simple_shear --set time.scheme=rkc --set time.t_end=8.2",
                out),
            0)
      << slurp(out.string() + ".log");
  EXPECT_EQ(summary(out).at("stop_reason"), "t_end");
  clean(out);
}

TEST(Health, ARotationSolveThatFailsAtTheStiffFloorIsRetriedAtTheSafeOne) {
  // Found by the clean re-run of the stress campaign (2026-12-01): GSMB NH sphere, α = 3 %, Ca_s = 3,
  // planar hyperbolic flow, 1280 elements. With the −0.9 floor (falling back to −0.5 only when CG
  // stalls) Newton failed after 100 steps at γ̇t = 1.0167 (residual 6.4e-6 rad), from a fresh start
  // too, and the run stopped with solver_failure; started again at −0.5 throughout it converges.
  const fs::path out = scratch("stiff-floor");
  EXPECT_EQ(run("--set mesh.level=3 --set mesh.shape=sphere --set wall.model=gsmb --set wall.thickness=0.03 "
                "--set wall.law=nh --set flow.ca_s=3 --set flow.type=planar_hyperbolic --set time.scheme=rkc "
                "--set time.t_end=1.1",
                out),
            0)
      << slurp(out.string() + ".log");
  EXPECT_EQ(summary(out).at("stop_reason"), "t_end");
  clean(out);
}

TEST(Health, AFixedStepAboveTheEstimateWarnsAndStopsBeforeTheVolumeDriftsOrNaN) {
  const fs::path out = scratch("fixed-dt");
  const int code = run(kOverStepped + "--set time.t_end=2 --set time.dt=" + std::to_string(1.5 * over_stepped_estimate()), out);
  EXPECT_EQ(code, 3) << slurp(out.string() + ".log");
  EXPECT_EQ(summary(out).at("stop_reason"), "blow_up");
  EXPECT_NE(slurp(out.string() + ".log").find("stability estimate"), std::string::npos);  // warned at start
  EXPECT_EQ(slurp(out / "timeseries.csv").find("nan"), std::string::npos);
  for (const auto& row : series(out)) EXPECT_LT(std::abs(row.at("volume_drift")), 1e-3) << "t = " << row.at("t");
  const auto ck = capsflow::io::read_checkpoint(out / "checkpoint.h5");  // the kept state is healthy
  const double v = capsflow::enclosed_volume(capsflow::SurfaceMesh{ck.positions, ck.triangles});
  const double v0 = capsflow::enclosed_volume(capsflow::SurfaceMesh{ck.reference_positions, ck.triangles});
  EXPECT_LT(std::abs(v / v0 - 1), 1e-3);
  // Caught by the geometric growth of the drift (health/instability_watch.hpp), not by the 1e-3
  // runaway check: measured 7.8e-6 at the stop (2026-11-30); 1e-4 leaves 10× on either side.
  EXPECT_NE(slurp(out.string() + ".log").find("growing"), std::string::npos);
  EXPECT_LT(std::abs(v / v0 - 1), 1e-4);
  clean(out);
}

TEST(Health, WithoutTheVolumeCorrectionAnOverSteppedRunStopsBeforeTheDriftPasses1e3) {
  // The same over-stepped case with fluid.volume_correction = false. Measured before the rate watch
  // (2026-11-30): the instability saturates in grid-scale folds and the run reached t_end = 2 with exit 0
  // and a −3.6 % volume drift. The same scene at dt = "auto" is healthy and must run to t_end.
  const std::string tiny = kOverStepped + "--set fluid.volume_correction=false --set time.t_end=2 ";
  const fs::path out = scratch("fixed-dt-uncorrected");
  EXPECT_EQ(run(tiny + "--set time.dt=" + std::to_string(1.5 * over_stepped_estimate()), out), 3) << slurp(out.string() + ".log");
  EXPECT_EQ(summary(out).at("stop_reason"), "blow_up");
  EXPECT_NE(slurp(out.string() + ".log").find("drift rate"), std::string::npos);  // the rate watch, not a runaway check
  EXPECT_EQ(slurp(out / "timeseries.csv").find("nan"), std::string::npos);
  // The bound: measured 5.3e-4 at the stop (γ̇t = 0.55).
  for (const auto& row : series(out)) EXPECT_LT(std::abs(row.at("volume_drift")), 1e-3) << "t = " << row.at("t");
  clean(out);
  const fs::path healthy = scratch("auto-dt-uncorrected");
  EXPECT_EQ(run(tiny, healthy), 0) << slurp(healthy.string() + ".log");
  EXPECT_EQ(summary(healthy).at("stop_reason"), "t_end");
  clean(healthy);
}

TEST(Health, SafetyFactorAboveTheMeasuredStableRangeIsRefused) {
  const fs::path out = scratch("safety");
  EXPECT_EQ(run("--set time.dt_safety=1.4 --set time.t_end=0.1", out), 1);
  EXPECT_NE(slurp(out.string() + ".log").find("time.dt_safety"), std::string::npos);
  EXPECT_FALSE(fs::exists(out / "summary.json"));
  clean(out);
}

TEST(Health, HeunAutoStepIsStableOnElongatedSpheroidsItsConstantWasNotCalibratedFor) {
  // Heun's calibrated constant covers a/b ≤ 1.4; on a membrane at a/b = 4 the automatic step
  // alone blew up at γ̇t = 0.48 (measured 2026-11-30 before the measured spectral radius joined
  // it). With 2/ρ from the power iteration as a second bound it is stable.
  const fs::path out = scratch("ab4-membrane");
  ASSERT_EQ(run("--set mesh.aspect=4 --set wall.model=membrane --set time.scheme=heun --set time.t_end=2", out), 0)
      << slurp(out.string() + ".log");
  const auto s = summary(out);
  EXPECT_EQ(s.at("scheme"), "heun");
  EXPECT_EQ(s.at("stop_reason"), "t_end");
  EXPECT_LT(std::abs(s.at("volume_drift").get<double>()), 1e-6);  // the bound (measured 5.7e-10)
  clean(out);
}

TEST(Health, StopAtSteadyWaitsForTheShapeToSettle) {
  // scenes/quick.toml met the paper's area criterion at γ̇t = 1.05 (D13 = 0.1105) and stopped there,
  // while D13 went on to 0.1158 by γ̇t = 4. With the full-window and D_ij-plateau tests a
  // stop, if any, must come with D13 within 2e-3 of its value at γ̇t = 4 of an uninterrupted run
  // (twice the 1e-3 plateau tolerance per unit time: the drift left after the plateau test).
  const std::string scene = std::string(CAPSFLOW_SOURCE_DIR) + "/scenes/quick.toml";
  const fs::path full = scratch("steady-full"), stop = scratch("steady-stop");
  ASSERT_EQ(run(scene + " --set time.t_end=4", full), 0);
  ASSERT_EQ(run(scene + " --set time.t_end=4 --set time.stop_at_steady=true", stop), 0);
  const auto f = summary(full), s = summary(stop);
  EXPECT_GT(s.at("t").get<double>(), 2.0 - 1e-9);  // never before the minimum time
  if (s.at("stop_reason") == "steady") {
    EXPECT_LT(std::abs(s.at("D13").get<double>() - f.at("D13").get<double>()), 2e-3) << s.at("t");
  }
  clean(full), clean(stop);
}
