// The RKC2 time scheme end to end against Heun: accuracy and cost on the paper's case at 1280
// elements, stability on an elongated spheroid the Heun constant was not calibrated for,
// restart equivalence, and the error falling with the tolerance.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fmt/core.h>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "capsflow/core/io/checkpoint.hpp"
#include "run_capsflow.hpp"

namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) { return capsflow_test::scratch("schemes", name); }
using capsflow_test::run;
using capsflow_test::summary;

// timeseries.csv as t → (column → value).
std::map<double, std::map<std::string, double>> series(const fs::path& dir) {
  std::map<double, std::map<std::string, double>> out;
  for (auto& row : capsflow_test::series_rows(dir)) out[std::round(row["t"] * 1e6) / 1e6] = row;
  return out;
}

double max_d13_difference(const fs::path& a, const fs::path& b, int* compared) {
  const auto sa = series(a), sb = series(b);
  double worst = 0;
  *compared = 0;
  for (const auto& [t, row] : sa) {
    auto it = sb.find(t);
    if (it == sb.end()) continue;
    worst = std::max(worst, std::abs(row.at("D13") - it->second.at("D13")));
    ++*compared;
  }
  return worst;
}

// `capsflow run --restart DIR/checkpoint.h5 --set time.t_end=T_END` into DIR, 2 threads, the log
// appended to DIR.log2; the exit code.
int continue_run(const fs::path& dir, const std::string& t_end) {
  const std::string cmd = std::string(CAPSFLOW_EXE) + " run --threads 2 --restart " + (dir / "checkpoint.h5").string() +
                          " --set time.t_end=" + t_end + " >> " + dir.string() + ".log2 2>&1";
  return std::system(cmd.c_str());
}

}  // namespace

// The paper's case (GSMB GH, α = 3 %, Ca_v = 0.003, a/b = 1.4) at 1280 elements to γ̇t = 2 — the
// built-in default scene.
TEST(TimeSchemes, RkcMatchesQuarterStepHeunWithFarFewerEvaluations) {
  const fs::path ref = scratch("heun-quarter"), heun = scratch("heun-auto"), rkc = scratch("rkc"), fast = scratch("rkc-5e-5");
  ASSERT_EQ(run("--set time.scheme=heun --set time.dt_safety=0.175", ref), 0);  // 1/4 of the auto step
  ASSERT_EQ(run("--set time.scheme=heun", heun), 0);
  ASSERT_EQ(run("--set time.scheme=rkc", rkc), 0);  // RKC2 at its "auto" tolerance
  ASSERT_EQ(run("--set time.scheme=rkc --set time.tolerance=5e-5", fast), 0);
  EXPECT_EQ(summary(rkc).at("scheme"), "rkc");
  int n = 0;
  // RKC2's "auto" tolerance is chosen for 1e-4 on D_ij on every paper case, including walls that fold
  // at the mesh scale (docs/time-integration.md §5.6–5.3); this wall folds but does not crease, so
  // "auto" keeps 1e-5 and gives 4.1e-5 with dense output (measured 2026-12-02; 3.5e-5
  // when steps landed on every output time; time.tolerance = 1e-6 gives 1.0e-5).
  EXPECT_LT(max_d13_difference(ref, rkc, &n), 1e-4);
  EXPECT_TRUE(summary(rkc).at("time_tolerance").at("rewind").is_null());
  EXPECT_EQ(n, 21);  // every output time, t = 0, 0.1, ..., 2 (between steps: dense output)
  // 5e-5 kept 8.8e-5 while steps landed on every output time; with dense output its steps are
  // longer and it gives 1.04e-4 (2026-12-02): one reason RKC2's "auto" is 1e-5. 2e-4 bounds it.
  EXPECT_LT(max_d13_difference(ref, fast, &n), 2e-4);
  const long e_heun = summary(heun).at("rhs_evaluations");
  const long e_rkc = summary(rkc).at("rhs_evaluations"), e_fast = summary(fast).at("rhs_evaluations");
  // Measured 1997 / 366 = 5.46 at RKC2's "auto" tolerance with dense output (2026-12-02;
  // 1997 / 410 = 4.9 when steps landed on every output time, 1997 / 602 = 3.3 at 1e-6; Heun's
  // automatic step includes 2/ρ since 8710966: docs/time-integration.md §5.6). The floor
  // is 5× with D13 within 1e-4 (asserted above): RKC2's "auto" meets it with 8 % to spare.
  EXPECT_GE(static_cast<double>(e_heun) / e_rkc, 5.0) << e_heun << " vs " << e_rkc;
  EXPECT_GE(static_cast<double>(e_heun) / e_fast, 5.0) << e_heun << " vs " << e_fast;
  EXPECT_LT(std::abs(summary(rkc).at("volume_drift").get<double>()), 1e-12);  // projected every step
  // The default, scheme "auto": ROCK4 on this wall and mesh (analytic spectral radius 461, below
  // 800: stepping/auto_scheme.hpp), at its "auto" tolerance, 2e-3 at 1 280 elements
  // (stepping/auto_tolerance.hpp), with the grid-scale-filtered estimate (§5.8): measured 296
  // evaluations (1997 / 296 = 6.7) and D_ij within 6e-6. The same bounds: 1e-4 and 5×.
  const fs::path rock4 = scratch("default-rock4");
  ASSERT_EQ(run("", rock4), 0);
  EXPECT_EQ(summary(rock4).at("scheme"), "rock4");
  EXPECT_DOUBLE_EQ(summary(rock4).at("time_tolerance").at("in_force").get<double>(), 2e-3);
  EXPECT_LT(max_d13_difference(ref, rock4, &n), 1e-4);
  EXPECT_EQ(n, 21);
  const long e_rock4 = summary(rock4).at("rhs_evaluations");
  EXPECT_GE(static_cast<double>(e_heun) / e_rock4, 5.0) << e_heun << " vs " << e_rock4;
  for (const auto& p : {ref, heun, rkc, fast, rock4}) fs::remove_all(p), fs::remove(p.string() + ".log");
}

// time.scheme = "auto" (stepping/auto_scheme.hpp, docs/time-integration.md §5.2) must give ROCK4
// where the 1e-4-with-5×-fewer-evaluations target needs it (the creasing Table 1 walls at 1 280 and 5 120
// elements: RKC2 costs 2.9–4.9× fewer evaluations than Heun there, under the 5× asked) and RKC2
// where ROCK4 costs more (Fig. 4 at 5 120 elements, 1.27×), above all at the floors' 81 920
// elements (ROCK4: 4 003 evaluations against 2 034) and on stiff walls (Ca_s = 0.01: 2.6×). A
// continued run keeps the plan its checkpoint holds, even where its new keys would choose another.
TEST(TimeSchemes, AutoSchemeIsRock4WhereAccuracySetsTheStepAndRkc2WhereStabilityDoes) {
  const std::string scenes = std::string(CAPSFLOW_SOURCE_DIR) + "/scenes/";
  const std::vector<std::pair<std::string, std::string>> cases{
      {"paper_table1_nh_gsmb_alpha3.toml --set mesh.level=3", "rock4"},
      {"paper_table1_nh_gsmb_alpha3.toml --set mesh.level=4", "rock4"},
      {"paper_table1_nh_membrane.toml --set mesh.level=4", "rock4"},
      {"paper_fig4_gh_alpha3.toml --set mesh.level=4", "rkc"},
      {"paper_fig4_gh_alpha3.toml --set mesh.level=6", "rkc"},
      {"paper_table1_nh_membrane.toml --set mesh.level=3 --set flow.ca_s=0.01", "rkc"},
      {"paper_table1_nh_gsmb_alpha3.toml --set mesh.level=3 --set time.dt=0.001", "rkc"}};  // a fixed step
  const fs::path dir = scratch("auto-scheme"), logs = scratch("auto-scheme-info");
  fs::create_directories(logs);
  for (const auto& [args, expected] : cases) {
    const capsflow_test::Result info = capsflow_test::capsflow("info " + scenes + args, logs);
    ASSERT_EQ(info.code, 0) << args;
    EXPECT_NE(info.out.find("time scheme     " + expected + " (auto"), std::string::npos) << args << "\n" << info.out;
  }
  // The run makes the same choice, and its checkpoint keeps the plan: continued at Ca_s = 0.01,
  // which a new run would take with RKC2 (above), it stays ROCK4, and says so.
  ASSERT_EQ(run(scenes + "paper_table1_nh_gsmb_alpha3.toml --set mesh.level=2 --set time.t_end=0.125", dir), 0);
  EXPECT_EQ(summary(dir).at("scheme"), "rock4");
  const std::string cmd = std::string(CAPSFLOW_EXE) + " run --threads 2 --restart " + dir.string() +
                          " --set time.t_end=0.25 --set flow.ca_s=0.01 >> " + dir.string() + ".log2 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_EQ(summary(dir).at("scheme"), "rock4");
  EXPECT_EQ(summary(dir).at("scene").at("time").at("scheme"), "auto");  // the scene as written
  EXPECT_NE(capsflow_test::slurp(dir.string() + ".log2").find("time scheme: rock4 (kept from the checkpoint: auto:"), std::string::npos);
  EXPECT_EQ(summary(dir).at("scene").at("flow").at("ca_s").get<double>(), 0.01);
  capsflow_test::remove_run(dir);
  fs::remove(dir.string() + ".log2");
  fs::remove_all(logs);
}

// ROCK4's "auto" tolerance is 2e-3 × 1280/N, for a plain membrane 2e-3 × (1280/N)^(8/3)
// (stepping/auto_tolerance.hpp): the run resolves it from the element count of its mesh and its wall
// once the mesh is built, and reports it in summary.json; `capsflow info` gives the same value and
// the one past the creases.
TEST(TimeSchemes, Rock4AutoToleranceFollowsTheElementCount) {
  // 2e-3 · 4 = 8e-3; 4^(8/3) = 2^(16/3) = 40.31747…: 2e-3 · 40.31747 = 0.0806349, 2e-3 / 40.31747 = 4.96063e-5.
  const std::vector<std::tuple<int, std::string, double>> cases{
      {2, "gsmb", 8e-3}, {3, "gsmb", 2e-3}, {2, "membrane", 0.0806349}, {3, "membrane", 2e-3}, {4, "membrane", 4.96063e-5}};
  for (const auto& [level, wall, expected] : cases) {
    const std::string what = wall + " at level " + std::to_string(level);
    const fs::path dir = scratch("rock4-tolerance-" + wall + std::to_string(level));
    const std::string args = "--set time.scheme=rock4 --set time.t_end=0.01 --set wall.model=" + wall +
                             " --set mesh.level=" + std::to_string(level);
    ASSERT_EQ(run(args, dir), 0) << what;
    // The literals above have 6 significant digits: 1e-6 relative.
    const nlohmann::json tolerance = summary(dir).at("time_tolerance");
    EXPECT_NEAR(tolerance.at("in_force").get<double>(), expected, 1e-6 * expected) << what;
    EXPECT_TRUE(tolerance.at("creases_seen_at").is_null()) << what;  // the built-in spheroid at γ̇t = 0.01
    // `capsflow info` says the same (printed with 6 digits) and 2e-3 past the creases, where that
    // is looser than the value before them (only the membrane at level 4 here).
    const capsflow_test::Result info = capsflow_test::capsflow("info " + args, dir);
    ASSERT_EQ(info.code, 0) << what;
    const std::string said = expected < 2e-3 ? fmt::format("tolerance auto: {:g} ℓ; 0.002 ℓ from where the wall creases", expected)
                                             : fmt::format("tolerance auto: {:g} ℓ)", expected);
    EXPECT_NE(info.out.find(said), std::string::npos) << what << "\n" << info.out;
    fs::remove_all(dir), fs::remove(dir.string() + ".log");
  }
}

TEST(TimeSchemes, RkcIsStableOnTheAspectFourSpheroid) {
  // The Heun constant was calibrated on a/b ≤ 1.4: at a/b = 4 its auto step loses 2.3 % of the
  // volume by γ̇t = 1. RKC takes its stages from the measured spectral radius.
  const fs::path rkc = scratch("ab4");
  ASSERT_EQ(run("--set mesh.aspect=4 --set time.scheme=rkc", rkc), 0);
  const nlohmann::json s = summary(rkc);
  EXPECT_EQ(s.at("stop_reason"), "t_end");
  EXPECT_LT(std::abs(s.at("volume_drift").get<double>()), 1e-6);  // the bound
  // The power iteration sees the stiffness the calibrated constant misses on this shape (measured
  // 1336 against 2/Δt_Heun ≈ 700 at γ̇t = 2, 2026-11-30; Heun at 0.2 × its step, 6539 evaluations,
  // agrees with this run's D13 within 5e-5 at every output).
  EXPECT_GT(s.at("spectral_radius").get<double>(), 1.2 * s.at("spectral_radius_analytic").get<double>());
  fs::remove_all(rkc), fs::remove(rkc.string() + ".log");
}

// The rotation solve per kind of evaluation (summary.json timing.iterations.by_evaluation): the
// kinds add up to the run's totals, and an RKC run's later stages, started from the stage
// predictor (docs/time-integration.md §5.6), take about one Newton step each.
TEST(TimeSchemes, RotationSolveIsCountedPerKindOfEvaluation) {
  const fs::path p = scratch("by-kind");
  ASSERT_EQ(run("--set mesh.level=2 --set time.scheme=rkc --set time.t_end=0.3", p), 0);
  const nlohmann::json it = summary(p).at("timing").at("iterations");
  const nlohmann::json& kinds = it.at("by_evaluation");
  long evaluations = 0, newton = 0, cg = 0;
  for (const auto& [kind, c] : kinds.items()) {
    evaluations += c.at("evaluations").get<long>();
    newton += c.at("newton").get<long>();
    cg += c.at("rotation_cg").get<long>();
  }
  // Output rows between RKC's steps that write no velocities solve the wall alone (wall_solves).
  EXPECT_EQ(evaluations, summary(p).at("timing").at("rhs_evaluations").get<long>() + it.at("wall_solves").get<long>());
  EXPECT_EQ(newton, it.at("newton").get<long>());
  EXPECT_EQ(cg, it.at("rotation_cg").get<long>());
  ASSERT_TRUE(kinds.contains("predicted_stage") && kinds.contains("stage") && kinds.contains("probe"));
  const auto per_eval = [&](const char* k) {
    return kinds.at(k).at("newton").get<double>() / kinds.at(k).at("evaluations").get<double>();
  };
  // Measured (2026-12-02, 320 elements): 1.00 per predicted stage; without the predictor these
  // stages took 2.00 (Dynamics.RkcStagePredictorSaves…). A Newton step is the least a stage takes.
  EXPECT_LT(per_eval("predicted_stage"), 1.3);
  fs::remove_all(p), fs::remove(p.string() + ".log");
}

// ROCK4's stages are predicted too (StabilizedStepper::stage_hint for the recurrence and u_1, Rock4::finishing_hint
// after it): Table 1 α = 3 % at 320 elements to γ̇t = 2, where the wall folds and each unpredicted
// ROCK4 stage took 3.25 Newton steps (measured 2026-12-04, the build before the predictor). With
// it: 1.81 per predicted stage, and the same evaluations and D_ij (the Newton solve converges to
// its tolerance from either start).
TEST(TimeSchemes, Rock4StagesStartFromThePredictor) {
  const fs::path p = scratch("rock4-predicted");
  ASSERT_EQ(run(std::string(CAPSFLOW_SOURCE_DIR) + "/scenes/paper_table1_nh_gsmb_alpha3.toml" +
                    " --set mesh.level=2 --set time.scheme=rock4 --set time.t_end=2",
                p),
            0);
  const nlohmann::json kinds = summary(p).at("timing").at("iterations").at("by_evaluation");
  ASSERT_TRUE(kinds.contains("predicted_stage") && kinds.contains("stage"));
  const auto per_eval = [&](const char* k) {
    return kinds.at(k).at("newton").get<double>() / kinds.at(k).at("evaluations").get<double>();
  };
  const double predicted = kinds.at("predicted_stage").at("evaluations").get<double>();
  const double all = predicted + kinds.at("stage").at("evaluations").get<double>();
  EXPECT_GT(predicted / all, 0.6);  // all but Y_1 and y_{n+1} of each step: measured 96 of 126
  // 2.4 lies between 1.81 (measured) and the 3.25 every stage took without the predictor.
  EXPECT_LT(per_eval("predicted_stage"), 2.4);
  fs::remove_all(p), fs::remove(p.string() + ".log");
}

TEST(TimeSchemes, RkcRestartMatchesUninterruptedRun) {
  for (const std::string scheme : {"rkc", "rock4"}) {
    SCOPED_TRACE(scheme);
    const fs::path a = scratch("restart-a"), b = scratch("restart-b");
    // The first part must end where the uninterrupted run's steps land: with RKC's dense output a
    // checkpoint time (output times lie between steps). Times exact in binary: with 0.05 and
    // t_end = 0.15 it would not (3 × 0.05 = 0.15000000000000002): its last step lands an ulp short,
    // and the rotation solve, converged to its 1e-10 rad in one Newton step from the stage
    // predictor, turns that ulp into 1e-13 in the positions (measured 2.2e-13).
    const std::string base =
        "--set mesh.level=2 --set time.scheme=" + scheme + " --set output.every=0.0625 --set output.checkpoint_every=0.125";
    ASSERT_EQ(run(base + " --set time.t_end=0.3125", a), 0);
    ASSERT_EQ(run(base + " --set time.t_end=0.25", b), 0);
    ASSERT_EQ(continue_run(b, "0.3125"), 0);
    const auto ca = capsflow::io::read_checkpoint(a / "checkpoint.h5");
    const auto cb = capsflow::io::read_checkpoint(b / "checkpoint.h5");
    EXPECT_EQ(ca.step, cb.step);
    EXPECT_DOUBLE_EQ(cb.t, 0.3125);
    // Same thread count, same operations in the same order: bit for bit (1e-13 allows a library's
    // summation order).
    EXPECT_LT((ca.positions - cb.positions).cwiseAbs().maxCoeff(), 1e-13);
    EXPECT_EQ(summary(a).at("rhs_evaluations"), summary(b).at("rhs_evaluations"));
    for (const auto& p : {a, b}) fs::remove_all(p), fs::remove(p.string() + ".log");
    fs::remove(b.string() + ".log2");
  }
}

// Dense output (docs/time-integration.md §5.6): RKC's steps land on checkpoints and t_end only,
// and an output time inside a step is written from the step's interpolant, its wall (and velocity,
// when written) solved there and the right-hand side's warm starts put back. So how often a run
// writes does not move its trajectory: the same steps, the same final positions bit for bit, the
// same rows where both write one — with and without velocity fields, at λ = 1 and λ = 5.
TEST(TimeSchemes, RkcOutputsBetweenStepsDoNotMoveTheTrajectory) {
  const std::string base = "--set mesh.level=2 --set time.scheme=rkc --set time.t_end=1 --set output.checkpoint_every=0.5";
  for (const std::string& variant : {std::string(), std::string(" --set 'output.fields=[\"velocity\",\"load\"]'"),
                                    std::string(" --set fluid.viscosity_ratio=5 --set 'output.fields=[\"velocity\"]'")}) {
    const fs::path sparse = scratch("dense-sparse"), dense = scratch("dense-dense");
    ASSERT_EQ(run(base + variant + " --set output.every=0.5", sparse), 0) << variant;
    ASSERT_EQ(run(base + variant + " --set output.every=0.015625", dense), 0) << variant;  // 1/64
    const auto cs = capsflow::io::read_checkpoint(sparse / "checkpoint.h5");
    const auto cd = capsflow::io::read_checkpoint(dense / "checkpoint.h5");
    EXPECT_EQ(cs.step, cd.step) << variant;
    // The same operations in the same order: equal bit for bit.
    EXPECT_EQ((cs.positions - cd.positions).cwiseAbs().maxCoeff(), 0.0) << variant;
    const auto rs = series(sparse), rd = series(dense);
    EXPECT_EQ(rs.size(), 3u) << variant;   // t = 0, 0.5, 1
    EXPECT_EQ(rd.size(), 65u) << variant;  // every 1/64
    for (const auto& [t, row] : rs)
      for (const char* c : {"D12", "D13", "D23", "L1", "area", "volume", "E_membrane", "E_bending"})
        EXPECT_EQ(row.at(c), rd.at(t).at(c)) << variant << " t = " << t << " " << c;
    // More rows than step ends (the 44 steps measured would need 45 rows with t = 0): at least
    // rows − steps − 1 were written between steps.
    const long between_at_least = static_cast<long>(rd.size()) - cd.step - 1;
    EXPECT_GT(between_at_least, 0) << variant;
    // Evaluations: without velocities a row between steps solves only the wall (a wall solve, not
    // an evaluation); with them it evaluates once (none where an output time is a step's end).
    const long es = summary(sparse).at("rhs_evaluations"), ed = summary(dense).at("rhs_evaluations");
    const long ws = summary(sparse).at("timing").at("iterations").at("wall_solves");
    const long wd = summary(dense).at("timing").at("iterations").at("wall_solves");
    EXPECT_EQ(ws, 0) << variant;  // every sparse row is at a step's end
    if (variant.find("velocity") == std::string::npos) {
      EXPECT_EQ(ed, es);
      EXPECT_GE(wd, between_at_least);
      EXPECT_LE(wd, 62);  // the 65 rows but t = 0, 0.5, 1 (steps land on checkpoints)
    } else {
      EXPECT_EQ(wd, 0) << variant;
      EXPECT_GE(ed - es, between_at_least) << variant;
      EXPECT_LE(ed - es, 62) << variant;
    }
    for (const auto& p : {sparse, dense}) fs::remove_all(p), fs::remove(p.string() + ".log");
  }
}

TEST(TimeSchemes, RkcErrorFallsWithTheTolerance) {
  // 320 elements to γ̇t = 1 against Heun at a quarter of its auto step; RKC2, then ROCK4 (whose
  // tolerance bounds its embedded third-order estimate: looser numbers for the same accuracy).
  // ROCK4 from 1e-3: above its "auto" for this mesh (8e-3) a run is a dozen long steps and its
  // error depends on where they fall more than on the tolerance (filtered estimate, measured:
  // 1e-1, 3e-2, 1e-2 gave 3.2e-5, 2.7e-5, 1.0e-4; 1e-3, 1e-4, 1e-5 give 7.9e-6, 1.4e-6, 5.0e-7 with
  // 149, 173, 231 evaluations).
  const std::string base = "--set mesh.level=2 --set time.t_end=1";
  const fs::path ref = scratch("sweep-ref");
  ASSERT_EQ(run(base + " --set time.scheme=heun --set time.dt_safety=0.175", ref), 0);
  for (const auto& [scheme, tolerances] : std::vector<std::pair<std::string, std::vector<std::string>>>{
           {"rkc", {"1e-3", "1e-4", "1e-5"}}, {"rock4", {"1e-3", "1e-4", "1e-5"}}}) {
    double prev = INFINITY;
    long prev_evals = 0;
    for (const std::string& tol : tolerances) {
      SCOPED_TRACE(scheme);
      const fs::path p = scratch(std::string("sweep-") + tol);
      ASSERT_EQ(run(base + " --set time.scheme=" + scheme + " --set time.tolerance=" + tol, p), 0);
      int n = 0;
      const double err = max_d13_difference(ref, p, &n);
      EXPECT_LT(err, prev) << "tolerance " << tol;  // strictly more accurate
      EXPECT_GT(summary(p).at("rhs_evaluations").get<long>(), prev_evals) << "tolerance " << tol;  // and dearer
      prev = err;
      prev_evals = summary(p).at("rhs_evaluations");
      fs::remove_all(p), fs::remove(p.string() + ".log");
    }
  }
  fs::remove_all(ref), fs::remove(ref.string() + ".log");
}

// time.tolerance = "auto" (docs/time-integration.md §5.3): where the wall creases at the mesh scale
// the run starts again from t = 0 at 5e-7 — and is then that run, row for row, up to the time where
// the discarded pass saw the creases; after it, the loose tolerance again. Where the wall does not
// crease, it is the run at 1e-5. Table 1's GSMB α = 3 % case at 1280 elements creases at γ̇t ≈ 1.26
// (facet angles 81°, measured 2026-12-04); the built-in scene folds from 1.35 but never creases
// (facet angles ≤ 54°).
TEST(TimeSchemes, AutoToleranceIsTheTightRunWhereTheWallCreasesAndTheLooseOneElsewhere) {
  const fs::path aut = scratch("auto-creases"), tight = scratch("auto-tight"), smooth = scratch("auto-smooth"),
                 loose = scratch("auto-loose");
  const std::string creasing = std::string(CAPSFLOW_SOURCE_DIR) + "/scenes/paper_table1_nh_gsmb_alpha3.toml" +
                               " --set mesh.level=3 --set time.t_end=1.5 --set time.scheme=rkc";  // "auto" takes ROCK4 here
  ASSERT_EQ(run(creasing, aut), 0);
  ASSERT_EQ(run(creasing + " --set time.tolerance=5e-7", tight), 0);
  const nlohmann::json sa = summary(aut), sb = summary(tight);
  const nlohmann::json& rewind = sa.at("time_tolerance").at("rewind");
  ASSERT_FALSE(rewind.is_null());
  const double t_creases = rewind.at("t").get<double>();
  EXPECT_GT(t_creases, 1.0);  // measured 1.26: where the facet angles pass 80°
  EXPECT_LT(t_creases, 1.4);  // leaves rows after it to compare
  const auto a = capsflow_test::series_rows(aut), b = capsflow_test::series_rows(tight);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), 16u);  // t = 0, 0.1, …, 1.5: the discarded loose rows are gone
  int after = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].at("t") <= t_creases) {
      for (const auto& [column, value] : a[i]) {
        if (column == "wall_seconds") continue;
        EXPECT_EQ(value, b[i].at(column)) << column << " at row " << i;  // the same run: bit for bit
      }
    } else {
      ++after;
      // Past the creases, the loose tolerance: no longer the tight run, but within the 1e-4 that
      // both keep against the quarter-step Heun reference (measured 3.1e-5 and 3.9e-5 to γ̇t = 5).
      for (const char* d : {"D12", "D13", "D23"}) EXPECT_NEAR(a[i].at(d), b[i].at(d), 1e-4) << d << " at row " << i;
    }
  }
  EXPECT_GE(after, 1);
  EXPECT_EQ(sa.at("time_tolerance").at("in_force"), 1e-5);  // the loose one again at the end
  // The cost is counted: the discarded evaluations are in the run's total, and the part past the
  // creases is cheaper than the tight run's.
  const long kept = sa.at("rhs_evaluations").get<long>() - rewind.at("rhs_evaluations").get<long>();
  EXPECT_LT(kept, sb.at("rhs_evaluations").get<long>());
  EXPECT_EQ(sa.at("timing").at("rhs_evaluations").get<long>(), kept);  // the table: the kept run

  ASSERT_EQ(run("--set time.t_end=1.6 --set time.scheme=rkc", smooth), 0);
  ASSERT_EQ(run("--set time.t_end=1.6 --set time.scheme=rkc --set time.tolerance=1e-5", loose), 0);
  const auto c = capsflow_test::series_rows(smooth), d = capsflow_test::series_rows(loose);
  ASSERT_EQ(c.size(), d.size());
  for (size_t i = 0; i < c.size(); ++i) EXPECT_EQ(c[i].at("D13"), d[i].at("D13")) << "row " << i;
  EXPECT_GT(c.back().at("grid_oscillation"), 0.033);  // it does fold (the monitors' threshold) ...
  EXPECT_TRUE(summary(smooth).at("time_tolerance").at("rewind").is_null());  // ... but is not rewound
  EXPECT_EQ(summary(smooth).at("rhs_evaluations"), summary(loose).at("rhs_evaluations"));
  for (const auto& p : {aut, tight, smooth, loose}) capsflow_test::remove_run(p);
}

// A run continued from a checkpoint written before the wall creased rewinds in its own folder as
// the uninterrupted run does, and a checkpoint written after the rewind continues at 1e-6.
TEST(TimeSchemes, AutoToleranceRewindSurvivesRestarts) {
  const fs::path whole = scratch("auto-whole"), parts = scratch("auto-parts");
  // Every t_end below is a checkpoint time, where the uninterrupted run's steps land too (with
  // RKC's dense output, output times lie between steps), and exact in binary.
  const std::string base = std::string(CAPSFLOW_SOURCE_DIR) + "/scenes/paper_table1_nh_gsmb_alpha3.toml" +
                           " --set mesh.level=3 --set output.checkpoint_every=0.125 --set time.scheme=rkc";
  ASSERT_EQ(run(base + " --set time.t_end=1.5", whole), 0);
  ASSERT_EQ(run(base + " --set time.t_end=1", parts), 0);  // before the creases (γ̇t ≈ 1.26)
  EXPECT_TRUE(summary(parts).at("time_tolerance").at("rewind").is_null());
  const auto restart = [&](const std::string& t_end) { return continue_run(parts, t_end); };
  ASSERT_EQ(restart("1.125"), 0);  // still before: loose
  EXPECT_TRUE(summary(parts).at("time_tolerance").at("rewind").is_null());
  ASSERT_EQ(restart("1.5"), 0);  // rewinds to t = 0 in this folder
  const auto a = capsflow::io::read_checkpoint(whole / "checkpoint.h5");
  const auto b = capsflow::io::read_checkpoint(parts / "checkpoint.h5");
  EXPECT_EQ(a.step, b.step);
  // Same thread count, same operations in the same order: bit for bit (1e-13 allows a library's
  // summation order, as RkcRestartMatchesUninterruptedRun).
  EXPECT_LT((a.positions - b.positions).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_EQ(capsflow_test::series_rows(whole).size(), capsflow_test::series_rows(parts).size());
  // After the rewind the checkpoint carries the creases' time: continuing it does not rewind again,
  // and past that time it goes on at the loose tolerance as the uninterrupted run does.
  ASSERT_EQ(restart("1.75"), 0);
  const nlohmann::json s = summary(parts);
  EXPECT_EQ(s.at("time_tolerance").at("in_force"), 1e-5);
  ASSERT_EQ(run(base + " --set time.t_end=1.75", whole), 0);
  const auto c = capsflow::io::read_checkpoint(whole / "checkpoint.h5");
  const auto d = capsflow::io::read_checkpoint(parts / "checkpoint.h5");
  EXPECT_EQ(c.step, d.step);
  EXPECT_LT((c.positions - d.positions).cwiseAbs().maxCoeff(), 1e-13);  // as above
  // The same step's time, carried through the checkpoint's JSON: 1e-12 allows the decimal round trip;
  // a second rewind would have moved it past 1.5.
  EXPECT_NEAR(s.at("time_tolerance").at("rewind").at("t").get<double>(),
              summary(whole).at("time_tolerance").at("rewind").at("t").get<double>(), 1e-12);
  for (const auto& p : {whole, parts}) capsflow_test::remove_run(p);
  fs::remove(parts.string() + ".log2");
}

// ROCK4's "auto" (docs/time-integration.md §5.4) needs no rewind: its tolerance up to the creases
// follows the mesh from t = 0, and the step where the run sees the wall crease hands the rest of
// the run to 2e-3. Table 1's NH membrane at 5 120 elements: 2e-3 × (1280/5120)^(8/3) = 4.96e-5 up
// to the creases (seen at γ̇t ≈ 0.52, facet angles 81°, measured 2026-12-04). A run continued from a
// checkpoint before the creases sees them at the same step as the uninterrupted run; one continued
// from after them keeps the looser tolerance.
TEST(TimeSchemes, Rock4AutoToleranceLoosensWhereTheWallCreasesAndSurvivesRestarts) {
  const fs::path whole = scratch("rock4-creases-whole"), parts = scratch("rock4-creases-parts");
  // Checkpoint times exact in binary, where the uninterrupted run's steps land too.
  const std::string base = std::string(CAPSFLOW_SOURCE_DIR) + "/scenes/paper_table1_nh_membrane.toml" +
                           " --set mesh.level=4 --set time.scheme=rock4 --set output.checkpoint_every=0.125";
  ASSERT_EQ(run(base + " --set time.t_end=0.625", whole), 0);
  const nlohmann::json w = summary(whole).at("time_tolerance");
  ASSERT_FALSE(w.at("creases_seen_at").is_null());
  const double t_creases = w.at("creases_seen_at").get<double>();
  EXPECT_GT(t_creases, 0.4);   // measured 0.52: the membrane buckles from γ̇t ≈ 0.36 ...
  EXPECT_LT(t_creases, 0.625);  // ... and creases before the end of this run
  EXPECT_EQ(w.at("in_force").get<double>(), 2e-3);  // looser past the creases: exactly the constant
  EXPECT_TRUE(w.at("rewind").is_null());             // ROCK4 does not rewind

  ASSERT_EQ(run(base + " --set time.t_end=0.375", parts), 0);  // before the creases
  const nlohmann::json p = summary(parts).at("time_tolerance");
  EXPECT_TRUE(p.at("creases_seen_at").is_null());
  EXPECT_NEAR(p.at("in_force").get<double>(), 4.96063e-5, 1e-10);  // 6 digits of 2e-3 / 4^(8/3)
  const auto restart = [&](const std::string& t_end) { return continue_run(parts, t_end); };
  ASSERT_EQ(restart("0.5"), 0);
  ASSERT_EQ(restart("0.625"), 0);  // sees the creases in this segment
  const auto a = capsflow::io::read_checkpoint(whole / "checkpoint.h5");
  const auto b = capsflow::io::read_checkpoint(parts / "checkpoint.h5");
  EXPECT_EQ(a.step, b.step);
  // Same thread count, same operations in the same order: bit for bit (1e-13 allows a library's
  // summation order, as RkcRestartMatchesUninterruptedRun).
  EXPECT_LT((a.positions - b.positions).cwiseAbs().maxCoeff(), 1e-13);
  // The same step's time through the checkpoint's JSON: 1e-12 allows the decimal round trip.
  EXPECT_NEAR(summary(parts).at("time_tolerance").at("creases_seen_at").get<double>(), t_creases, 1e-12);
  ASSERT_EQ(restart("0.75"), 0);  // from a checkpoint past the creases: the looser tolerance carried
  EXPECT_EQ(summary(parts).at("time_tolerance").at("in_force").get<double>(), 2e-3);
  EXPECT_NEAR(summary(parts).at("time_tolerance").at("creases_seen_at").get<double>(), t_creases, 1e-12);
  for (const auto& q : {whole, parts}) capsflow_test::remove_run(q);
  fs::remove(parts.string() + ".log2");
}

// A stage whose rotation solve fails is not the end of a run with error control: the step is
// rejected and tried again a quarter as long (run.cpp). A GSMB Skalak sphere (C = 10) at Ca_s = 10
// in planar hyperbolic flow, ROCK4: its fourth step (τ = 0.25 from γ̇t = 0.5) has a stage whose
// Newton solve stalls at 1.4e-3 rad; before the retry the run stopped there with `solver_failure`
// (RKC2 reaches t_end). The shorter step converges and the run reaches γ̇t = 1.
TEST(TimeSchemes, AStageWhoseRotationSolveFailsIsRetriedInAShorterStep) {
  const fs::path dir = scratch("solver-retry");
  ASSERT_EQ(run("--set mesh.level=3 --set wall.model=gsmb --set wall.thickness=0.03 --set wall.law=skalak "
                "--set wall.skalak_c=10 --set flow.ca_s=10 --set mesh.shape=sphere --set flow.type=planar_hyperbolic "
                "--set time.t_end=1 --set time.scheme=rock4",
                dir),
            0);
  const nlohmann::json s = summary(dir);
  EXPECT_EQ(s.at("stop_reason"), "t_end");
  EXPECT_GE(s.at("rejected_steps").get<long>(), 1);  // the retried step counts as rejected
  EXPECT_NE(capsflow_test::slurp(dir.string() + ".log").find("tried again a quarter as long"), std::string::npos);
  fs::remove_all(dir), fs::remove(dir.string() + ".log");
}
