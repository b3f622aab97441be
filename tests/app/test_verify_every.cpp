// fluid.verify_every (docs/scene-and-output.md §2.6): the far field re-summed directly every N
// evaluations of a run, reported in timeseries.csv and summary.json, for the single layer and (with
// fluid.viscosity_ratio ≠ 1) the double layer. The check must pass at the order the tolerance
// calls for and fail — with a warning — when the FMM order is forced too low.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "run_capsflow.hpp"

namespace fs = std::filesystem;

namespace {

using capsflow_test::capsflow;
using capsflow_test::Result;
struct TempDir : capsflow_test::TempDir {
  TempDir() : capsflow_test::TempDir("verify") {}
};

nlohmann::json summary_of(const fs::path& dir) {
  std::ifstream in(dir / "summary.json");
  return nlohmann::json::parse(in);
}

// Header and rows of timeseries.csv.
std::vector<std::vector<std::string>> csv_of(const fs::path& dir) {
  std::ifstream in(dir / "timeseries.csv");
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    rows.push_back(cells);
  }
  return rows;
}

// The default capsule on 1280 elements with the FMM forced (the automatic choice is direct at
// this size), a few steps. Tolerance 1e-5: the boundary integral asks the FMM for 2.5e-6, i.e.
// order 8 (fmm/calibration.hpp). 100 points per leaf: the calibrated leaves (400–1 300) would put
// the 1 920 sources in a few adjacent boxes, all summed directly, and no order could be too low.
const std::string kRun = "run --set mesh.level=3 --set fluid.backend=fmm --set fluid.tolerance=1e-5 --set time.t_end=0.02 "
                         "--set output.every=0.01 --set fluid.fmm_leaf_size=100 --threads 2";

}  // namespace

// fluid.tolerance = "auto" on the FMM back end (docs/boundary-integral.md §4.3.2): the run promises
// 1e-5, at the order 1e-5 calls for, and the direct check holds it to that promise; with a fixed
// step (no error control) the same run keeps 1e-6.
TEST(VerifyEvery, TheAutoToleranceIsTheFmmsPromiseInTheRunAndItsChecks) {
  TempDir d;
  const std::string run = "run --set mesh.level=3 --set fluid.backend=fmm --set time.t_end=0.02 --set output.every=0.01 "
                          "--set fluid.fmm_leaf_size=100 --set fluid.verify_every=1 --threads 2";
  const Result a = capsflow(run + " -o " + (d.path / "auto").string(), d.path);
  ASSERT_EQ(a.code, 0) << a.out;
  const nlohmann::json s = summary_of(d.path / "auto");
  EXPECT_EQ(s["far_field_tolerance"].get<double>(), 1e-5);
  EXPECT_EQ(s["fmm_order"], 8);  // as kRun's explicit 1e-5
  EXPECT_EQ(s["far_field_check"]["tolerance"].get<double>(), 1e-5);
  EXPECT_LT(s["far_field_check"]["worst_max_relative"].get<double>(), 1e-5);  // the promise holds
  EXPECT_EQ(s["far_field_check"]["above_tolerance"], 0);
  EXPECT_NE(s["backend_reason"].get<std::string>().find("the FMM at tolerance 1e-05"), std::string::npos);

  const Result f = capsflow(run + " --set time.dt=0.002 -o " + (d.path / "fixed").string(), d.path);
  ASSERT_EQ(f.code, 0) << f.out;
  const nlohmann::json g = summary_of(d.path / "fixed");
  EXPECT_EQ(g["far_field_tolerance"].get<double>(), 1e-6);
  EXPECT_EQ(g["fmm_order"], 9);  // 0.25 × 1e-6 (fmm/calibration.hpp)
  EXPECT_LT(g["far_field_check"]["worst_max_relative"].get<double>(), 1e-6);  // the 1e-6 promise holds
}

TEST(VerifyEvery, TheCalibratedOrderPassesAndATooLowOrderFailsWithAWarning) {
  TempDir d;
  const Result good = capsflow(kRun + " --set fluid.verify_every=1 -o " + (d.path / "good").string(), d.path);
  ASSERT_EQ(good.code, 0) << good.out;
  const nlohmann::json g = summary_of(d.path / "good");
  ASSERT_TRUE(g.contains("far_field_check")) << g.dump();
  const nlohmann::json& gc = g["far_field_check"];
  EXPECT_EQ(gc["backend"], "fmm");
  EXPECT_EQ(gc["fmm_order"], 8);
  EXPECT_EQ(g["fmm_order"], 8);
  EXPECT_EQ(g["fmm_leaf_size"], 100);  // the scene's fluid.fmm_leaf_size, honoured and reported
  // Every evaluation was checked (verify_every = 1).
  EXPECT_EQ(gc["checks"].get<long>(), g["rhs_evaluations"].get<long>());
  // The promise of fluid.tolerance: max node difference relative to max |v| below it.
  EXPECT_LT(gc["worst_max_relative"].get<double>(), 1e-5);
  EXPECT_EQ(gc["above_tolerance"], 0);
  // ... and not trivially: the FMM approximates something at this size (a check that compared a
  // sum with itself would give ~1e-16; order 8 is measured at ~1e-7 relative L2, calibration.hpp).
  EXPECT_GT(gc["worst_max_relative"].get<double>(), 1e-12);
  EXPECT_LE(gc["worst_rms_relative"].get<double>(), gc["worst_max_relative"].get<double>());
  EXPECT_EQ(good.out.find("far-field check"), std::string::npos) << good.out;  // no warning
  EXPECT_GT(g["timing"]["phases"]["bie_verify"].get<double>(), 0.0);

  // Order 4 against the same tolerance: ~1e-3 relative L2 (calibration.hpp), far above 1e-5.
  const Result bad =
      capsflow(kRun + " --set fluid.verify_every=1 --set fluid.fmm_order=4 -o " + (d.path / "bad").string(), d.path);
  ASSERT_EQ(bad.code, 0) << bad.out;  // a warning, not a stop
  const nlohmann::json b = summary_of(d.path / "bad");
  EXPECT_EQ(b["far_field_check"]["fmm_order"], 4);
  EXPECT_GT(b["far_field_check"]["worst_max_relative"].get<double>(), 1e-5);
  // Every check counts, not only the last one of each step (Heun makes two evaluations per step):
  // order 4 is ~100× above the tolerance on every state of this run (measured 1.2e-3 to 1.5e-3
  // at each of 21 outputs 0.001 apart), so every check exceeds it.
  EXPECT_EQ(b["far_field_check"]["above_tolerance"].get<long>(), b["far_field_check"]["checks"].get<long>());
  EXPECT_EQ(b["far_field_check"]["checks"].get<long>(), b["rhs_evaluations"].get<long>());
  // One warning line, however many checks exceeded.
  const std::string w = "far-field check at t = ";
  const auto first = bad.out.find(w);
  ASSERT_NE(first, std::string::npos) << bad.out;
  EXPECT_EQ(bad.out.find(w, first + 1), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("(FMM order 4)"), std::string::npos) << bad.out;

  // timeseries.csv: the latest check at every output row (t = 0, 0.01, 0.02).
  const auto rows = csv_of(d.path / "bad");
  ASSERT_EQ(rows.size(), 4u);
  const auto& h = rows[0];
  const auto col = std::find(h.begin(), h.end(), "far_field_check_max") - h.begin();
  ASSERT_LT(col, static_cast<long>(h.size()));
  EXPECT_EQ(h[static_cast<std::size_t>(col) + 1], "far_field_check_rms");
  for (std::size_t r = 1; r < rows.size(); ++r) EXPECT_GT(std::stod(rows[r][static_cast<std::size_t>(col)]), 1e-5) << r;
}

TEST(VerifyEvery, ChecksEveryNthEvaluationAndCostsNothingWhenOff) {
  TempDir d;
  const Result every3 = capsflow(kRun + " --set fluid.verify_every=3 -o " + (d.path / "e3").string(), d.path);
  ASSERT_EQ(every3.code, 0) << every3.out;
  const nlohmann::json s = summary_of(d.path / "e3");
  // Evaluations 0, 3, 6, ... of the run are checked (the first one, so that the t = 0 row has a value).
  const long evals = s["rhs_evaluations"].get<long>();
  EXPECT_EQ(s["far_field_check"]["checks"].get<long>(), (evals + 2) / 3);
  EXPECT_EQ(s["far_field_check"]["every"], 3);

  const Result off = capsflow(kRun + " -o " + (d.path / "off").string(), d.path);
  ASSERT_EQ(off.code, 0) << off.out;
  const nlohmann::json o = summary_of(d.path / "off");
  EXPECT_FALSE(o.contains("far_field_check"));
  EXPECT_EQ(o["timing"]["phases"]["bie_verify"].get<double>(), 0.0);  // not a single direct sum
  const auto rows = csv_of(d.path / "off");
  EXPECT_EQ(std::find(rows[0].begin(), rows[0].end(), "far_field_check_max"), rows[0].end());
  // λ = 1 has no double layer: no second check, column or key, even with verify_every on.
  const nlohmann::json s3 = summary_of(d.path / "e3");
  EXPECT_FALSE(s3.contains("double_layer_far_field_check"));
  EXPECT_EQ(csv_of(d.path / "e3")[0].size(), rows[0].size() + 2);  // the single layer's two columns only
}

// fluid.viscosity_ratio ≠ 1: the double layer's far field (its FMM of the unit constants D̃[1] and
// of the solve's first application, the same set-up and order as every GMRES application on that
// surface) is checked too, with its own columns, summary key and warning.
// Level 4 (7680 sources): at level 3 the stresslet's leaves of 800 points (fmm/calibration.hpp)
// leave almost every pair to the near field, and even order 4 agrees with direct to ~3e-9.
TEST(VerifyEvery, TheDoubleLayersFarFieldIsCheckedWhenTheViscosityRatioIsNotOne) {
  TempDir d;
  const std::string run = "run --set mesh.level=4 --set fluid.backend=fmm --set fluid.tolerance=1e-5 --set time.t_end=0.005 "
                          "--set output.every=0.005 --threads 2 --set fluid.viscosity_ratio=5 --set fluid.verify_every=1";
  const Result good = capsflow(run + " -o " + (d.path / "good").string(), d.path);
  ASSERT_EQ(good.code, 0) << good.out;
  const nlohmann::json g = summary_of(d.path / "good");
  ASSERT_TRUE(g.contains("double_layer_far_field_check")) << g.dump();
  const nlohmann::json& gc = g["double_layer_far_field_check"];
  EXPECT_EQ(gc["backend"], "fmm");
  // The stresslet FMM at the order for 0.25 × 1e-5 (fmm/calibration.hpp, the stresslet's table).
  EXPECT_GE(gc["fmm_order"].get<int>(), 8);
  // One check per right-hand-side evaluation: each evaluation sets the double layer's surface once.
  EXPECT_EQ(gc["checks"].get<long>(), g["rhs_evaluations"].get<long>());
  // The promise of fluid.tolerance (max node difference relative to the largest value; measured
  // 6e-7 at p = 9 on this run to t = 0.02) ...
  EXPECT_LT(gc["worst_max_relative"].get<double>(), 1e-5);
  EXPECT_EQ(gc["above_tolerance"], 0);
  // ... and not trivially: the FMM approximates something (a sum compared with itself gives ~1e-16).
  EXPECT_GT(gc["worst_max_relative"].get<double>(), 1e-12);
  EXPECT_EQ(good.out.find("far-field check at t"), std::string::npos) << good.out;  // no warning, either layer
  EXPECT_TRUE(g.contains("far_field_check"));  // the single layer's, as at λ = 1

  // Order 4 on both layers against tolerance 1e-5: the double layer's check must fail at every
  // evaluation (p = 4 is calibrated for 6e-3 relative L2, the stresslet's table; measured 2.7e-3
  // max, 1.0e-3 RMS on this run to t = 0.02) and warn once.
  const Result bad = capsflow(run + " --set fluid.fmm_order=4 -o " + (d.path / "bad").string(), d.path);
  ASSERT_EQ(bad.code, 0) << bad.out;  // a warning, not a stop
  const nlohmann::json b = summary_of(d.path / "bad");
  const nlohmann::json& bc = b["double_layer_far_field_check"];
  EXPECT_EQ(bc["fmm_order"], 4);
  EXPECT_GT(bc["worst_max_relative"].get<double>(), 1e-5);
  EXPECT_EQ(bc["above_tolerance"].get<long>(), bc["checks"].get<long>());
  EXPECT_EQ(bc["checks"].get<long>(), b["rhs_evaluations"].get<long>());
  const std::string w = "double-layer far-field check at t = ";
  const auto first = bad.out.find(w);
  ASSERT_NE(first, std::string::npos) << bad.out;
  EXPECT_EQ(bad.out.find(w, first + 1), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("(FMM order 4)", first), std::string::npos) << bad.out;

  // timeseries.csv: both layers' latest checks at every output row (t = 0, 0.005), the double
  // layer's columns right after the single layer's.
  const auto rows = csv_of(d.path / "bad");
  ASSERT_EQ(rows.size(), 3u);
  const auto& h = rows[0];
  const auto col = std::find(h.begin(), h.end(), "double_layer_far_field_check_max") - h.begin();
  ASSERT_LT(col, static_cast<long>(h.size()));
  EXPECT_EQ(h[static_cast<std::size_t>(col) - 1], "far_field_check_rms");
  EXPECT_EQ(h[static_cast<std::size_t>(col) + 1], "double_layer_far_field_check_rms");
  for (std::size_t r = 1; r < rows.size(); ++r) EXPECT_GT(std::stod(rows[r][static_cast<std::size_t>(col)]), 1e-5) << r;
}

TEST(VerifyEvery, TheWorstAndTheCountsSpanARestart) {
  TempDir d;
  const fs::path out = d.path / "r";
  const std::string low = " --set fluid.verify_every=1 --set fluid.fmm_order=4";
  const Result a = capsflow(kRun + low + " --set time.t_end=0.01 -o " + out.string(), d.path);
  ASSERT_EQ(a.code, 0) << a.out;
  const nlohmann::json s1 = summary_of(out);
  const Result b = capsflow("run --threads 2 --restart " + out.string() + " --set time.t_end=0.02", d.path);
  ASSERT_EQ(b.code, 0) << b.out;
  const nlohmann::json s2 = summary_of(out);
  // Both segments' checks are counted (rhs_evaluations is the whole run's), and the worst never
  // drops below the first segment's.
  EXPECT_EQ(s2["far_field_check"]["checks"].get<long>(), s2["rhs_evaluations"].get<long>());
  EXPECT_GT(s2["far_field_check"]["checks"].get<long>(), s1["far_field_check"]["checks"].get<long>());
  EXPECT_EQ(s2["far_field_check"]["above_tolerance"].get<long>(), s2["far_field_check"]["checks"].get<long>());
  EXPECT_GE(s2["far_field_check"]["worst_max_relative"].get<double>(), s1["far_field_check"]["worst_max_relative"].get<double>());
}
