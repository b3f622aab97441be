// The far-field back end (bie/backend_choice.hpp): the scene's request, and for "auto" each
// operator's crossover checked against the timings it was read from — the single layer's
// (perf/bie/crossover.jsonl: its own far field, direct against FMM, on a quiet machine) and the
// double layer's (perf/fmm/results/stresslet/crossover.jsonl and leaf.jsonl: the stresslet FMM
// against its direct sum) — not against the code's own constants; the single-precision pairs of
// the direct sum, and the source counts the operators pass.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>
#include <vector>

#include "capsflow/core/bie/backend_choice.hpp"
#include "capsflow/core/bie/double_layer.hpp"
#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/mesh/topology.hpp"
#include "capsflow/fmm/calibration.hpp"
#include "capsflow/fmm/direct_sum_mixed.hpp"

using namespace capsflow;

namespace {

std::vector<nlohmann::json> read_jsonl(const std::string& relative) {
  std::ifstream in(std::string(CAPSFLOW_SOURCE_DIR) + "/" + relative);
  std::vector<nlohmann::json> rows;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] == '{') rows.push_back(nlohmann::json::parse(line));
  return rows;
}

// Two timings closer than this are a tie: the quiet-machine medians of 3–5 repeats spread by
// 2–10 % between their fastest and slowest repeat (min_s/max_s in the data), so either choice
// is right there.
constexpr double kTie = 0.10;

// One size of the single layer's measurement: both back ends' far-field seconds.
struct Size {
  long sources = 0, nodes = 0;
  double direct = NAN, fmm = NAN;
  double c() const { return std::sqrt(static_cast<double>(sources) * static_cast<double>(nodes)); }
};

// perf/bie/crossover.jsonl by tolerance, then by mesh (base, level).
std::map<double, std::map<std::pair<std::string, int>, Size>> single_layer_timings() {
  std::map<double, std::map<std::pair<std::string, int>, Size>> t;
  for (const auto& r : read_jsonl("perf/bie/crossover.jsonl")) {
    Size& s = t[r["tol"].get<double>()][{r["base"].get<std::string>(), r["level"].get<int>()}];
    s.sources = r["sources"].get<long>();
    s.nodes = r["nodes"].get<long>();
    (r["backend"] == "direct" ? s.direct : s.fmm) = r["far_s"].get<double>();
  }
  return t;
}

// A leaf-size sweep (perf/fmm/results/*.jsonl: fmm_bench lines) checked against a kernel's default
// leaf: for every (sources, targets, order) case, the default must have been measured and cost at
// most (1 + slack) times the best leaf of that case. Only the orders whose default leaf is
// `only_leaf` are checked (0: all); returns the number of cases checked.
template <class Kernel>
std::size_t expect_default_leaf_near_best(const std::string& sweep, double slack, int only_leaf = 0) {
  std::map<std::tuple<long, long, int>, std::map<int, double>> by;  // (N, M, p) → leaf → seconds
  for (const auto& r : read_jsonl(sweep))
    by[{r["n"].get<long>(), r["ntrg"].get<long>(), r["order"].get<int>()}][r["leaf"].get<int>()] =
        r["setup_s"].get<double>() + r["eval_s"].get<double>();
  std::size_t checked = 0;
  for (const auto& [key, times] : by) {
    const auto& [n, ntrg, p] = key;
    const int leaf = fmm::default_leaf_size<Kernel>(p);
    if (only_leaf > 0 && leaf != only_leaf) continue;
    ++checked;
    double best = INFINITY;
    for (const auto& [l, t] : times) best = std::min(best, t);
    EXPECT_TRUE(times.count(leaf)) << sweep << ": leaf " << leaf << " was not measured at p = " << p;
    if (times.count(leaf)) {
      EXPECT_LE(times.at(leaf), (1 + slack) * best) << sweep << ": N = " << n << " × " << ntrg << ", p = " << p << ", leaf " << leaf;
    }
  }
  return checked;
}
}  // namespace

TEST(BackendChoice, AutoPicksTheFasterSingleLayerFarFieldAtEveryMeasuredSize) {
  const auto timings = single_layer_timings();
  ASSERT_EQ(timings.size(), 6u) << "perf/bie/crossover.jsonl: tolerances 1e-3 … 1e-8";
  int decided = 0;
  for (const auto& [tol, sizes] : timings) {
    ASSERT_EQ(sizes.size(), 4u) << tol;
    for (const auto& [mesh, s] : sizes) {
      ASSERT_FALSE(std::isnan(s.direct) || std::isnan(s.fmm)) << tol << " " << mesh.first << " " << mesh.second;
      if (std::abs(s.fmm - s.direct) < kTie * std::min(s.fmm, s.direct)) continue;  // a tie (above)
      ++decided;
      std::string why;
      const FarFieldBackend faster = s.direct < s.fmm ? FarFieldBackend::Direct : FarFieldBackend::Fmm;
      EXPECT_EQ(choose_backend(BackendRequest::Auto, FarFieldKernel::SingleLayer, s.sources, s.nodes, tol, &why), faster)
          << "tolerance " << tol << ", " << mesh.first << " level " << mesh.second << ": direct " << s.direct << " s, FMM "
          << s.fmm << " s; " << why;
    }
  }
  // 24 sizes, none a tie in the measured data (the closest 1.4× apart): the check is not vacuous.
  EXPECT_GE(decided, 20);
}

TEST(BackendChoice, TheSingleLayerCrossoverLiesBetweenTheMeasuredSizesOrSaysItIsExtrapolated) {
  // Per tolerance: the largest size at which direct was faster and the smallest at which the FMM
  // was (ties included, either way). A measured row's crossover must lie between them; where the
  // FMM never won, the row must say it is extrapolated and lie above every measured size.
  for (const auto& [tol, sizes] : single_layer_timings()) {
    double direct_max = 0, fmm_min = INFINITY;
    for (const auto& [mesh, s] : sizes) {
      if (s.direct < s.fmm) direct_max = std::max(direct_max, s.c());
      else fmm_min = std::min(fmm_min, s.c());
    }
    const SingleLayerCrossoverRow& row = single_layer_crossover(tol);
    const double c = static_cast<double>(row.crossover);
    EXPECT_GT(c, direct_max) << tol;
    EXPECT_EQ(row.measured, std::isfinite(fmm_min)) << tol;
    if (row.measured) {
      EXPECT_LE(c, fmm_min) << tol;
    }
  }
  // Tighter tolerances mean higher FMM orders at the same direct cost: never an earlier switch.
  for (double tol : {1e-3, 1e-4, 1e-5, 1e-6, 1e-7})
    EXPECT_LE(single_layer_crossover(tol).crossover, single_layer_crossover(tol / 10).crossover) << tol;
}

TEST(BackendChoice, TheReasonNamesTheCountsTheSideAndWhetherTheCrossoverWasMeasured) {
  std::string why;
  // 5 120 elements (7 680 sources, 2 562 nodes: sqrt = 4 436) at the default tolerance 1e-6:
  // direct, 0.0032 s against the FMM's 0.0044 s per far field (perf/bie/crossover.jsonl).
  EXPECT_EQ(choose_backend(BackendRequest::Auto, FarFieldKernel::SingleLayer, 7680, 2562, 1e-6, &why), FarFieldBackend::Direct);
  EXPECT_NE(why.find("7680 sources × 2562 targets is below"), std::string::npos) << why;
  EXPECT_NE(why.find("measured"), std::string::npos) << why;
  // 20 480 elements (30 720 sources, 10 242 nodes: sqrt = 17 738): the FMM, 0.043 s against 0.051 s.
  EXPECT_EQ(choose_backend(BackendRequest::Auto, FarFieldKernel::SingleLayer, 30720, 10242, 1e-6, &why), FarFieldBackend::Fmm);
  EXPECT_NE(why.find("above"), std::string::npos) << why;
  EXPECT_EQ(why.find("extrapolated"), std::string::npos) << why;  // every row is measured now
}

TEST(BackendChoice, TheDoubleLayerUsesTheStressletFmmsMeasuredCrossover) {
  // perf/fmm/results/stresslet/crossover.jsonl: sources = targets on the sphere, the stresslet
  // FMM's set-up and one evaluation against its direct sum, at orders 6, 9 and 12. The double
  // layer's back-end choice reads the crossover at kFmmToleranceMargin × fluid.tolerance (the
  // calibration's own rule, not the order the double layer runs: backend_choice.hpp); for each
  // measured order take the loosest fluid tolerance that maps to it.
  int decided = 0;
  for (const auto& r : read_jsonl("perf/fmm/results/stresslet/crossover.jsonl")) {
    const int p = r["order"].get<int>();
    double tol = NAN;
    for (const auto& row : fmm::kStressletCalibration)
      if (row.order == p) tol = row.tolerance / kFmmToleranceMargin;
    ASSERT_FALSE(std::isnan(tol)) << "order " << p << " has no row";
    ASSERT_EQ(fmm::order_for_tolerance<fmm::Stresslet>(kFmmToleranceMargin * tol), p);
    const double t_fmm = r["setup_s"].get<double>() + r["eval_s"].get<double>(), t_direct = r["direct_s"].get<double>();
    if (std::abs(t_fmm - t_direct) < kTie * std::min(t_fmm, t_direct)) continue;  // a tie
    ++decided;
    const long n = r["n"].get<long>();
    std::string why;
    EXPECT_EQ(choose_backend(BackendRequest::Auto, FarFieldKernel::DoubleLayer, n, n, tol, &why),
              t_direct < t_fmm ? FarFieldBackend::Direct : FarFieldBackend::Fmm)
        << "p = " << p << ", N = " << n << ": direct " << t_direct << " s, FMM " << t_fmm << " s; " << why;
    EXPECT_NE(why.find("stresslet"), std::string::npos) << why;
  }
  EXPECT_GE(decided, 12);  // 15 sizes, 1 tie (p = 9 at 16 000: 8.8 %)
}

// The double layer's FMM order is chosen by its error relative to the density (the Krylov
// operator's contract), and meets it: on a tilted a/b = 2 spheroid at 5 120 elements the FMM the
// double layer picks for fluid.tolerance = 1e-6 (p = 9) and for its inexact steps (p = 7) against
// the direct sum, for a smooth and a random density, in the nodal-area norm.
TEST(BackendChoice, TheDoubleLayersFmmOrderMeetsItsToleranceRelativeToTheDensity) {
  EXPECT_EQ(fmm::order_for_tolerance<fmm::Stresslet>(double_layer_fmm_tolerance(1e-6)), 9);
  EXPECT_EQ(fmm::order_for_tolerance<fmm::Stresslet>(double_layer_fmm_tolerance(2.5e-5, 1e-4)), 7);
  // Beyond the table: the image-relative request of before, 0.25 × the tolerance.
  EXPECT_EQ(double_layer_fmm_tolerance(1e-10), kFmmToleranceMargin * 1e-10);
  SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 4);
  m.vertices.col(2) *= 2.0;
  Points smooth(m.num_nodes(), 3), random = Points::Random(m.num_nodes(), 3);
  for (Eigen::Index i = 0; i < smooth.rows(); ++i) {
    const Vec3 x = m.vertices.row(i);
    smooth.row(i) << x[1] - 0.3 * x[2], x[0] * x[2], 1.0 + x[0] * x[0];
  }
  const Eigen::VectorXd w = nodal_areas(m);
  auto norm = [&](const Points& v) { return std::sqrt((w.array() * v.rowwise().squaredNorm().array()).sum()); };
  DoubleLayerOptions direct;
  direct.backend = BackendRequest::Direct;
  direct.reuse_identity_term = false;
  DoubleLayer ref(m.triangles, m.num_nodes(), direct);
  ref.set_surface(m.vertices);
  DoubleLayerOptions fmm_opt = direct;
  fmm_opt.backend = BackendRequest::Fmm;
  DoubleLayer D(m.triangles, m.num_nodes(), fmm_opt);
  D.set_surface(m.vertices);
  EXPECT_EQ(D.fmm_order(), 9);
  EXPECT_EQ(D.diagnostics().inexact_fmm_order, 7);
  for (const Points* u : {&smooth, &random}) {
    Points exact, fast, inexact;
    ref.apply(*u, exact);
    D.apply(*u, fast);
    D.apply(*u, inexact, 1e-4);
    // The promise: a quarter of the tolerance in L2 (measured 1.3e-8 and 1.7e-8 at this level:
    // perf/RESULTS.md §2.2) ...
    EXPECT_LT(norm(fast - exact) / norm(*u), 0.25e-6);
    // ... and of the inexact steps' allowance 1e-4 (measured 5.8e-7 and 5.7e-7).
    EXPECT_LT(norm(inexact - exact) / norm(*u), 0.25e-4);
  }
}

TEST(BackendChoice, TheStressletsDefaultLeafIsWithinTenPercentOfTheBestMeasured) {
  // perf/fmm/results/stresslet/leaf.jsonl: leaves of 200–800 points at p = 6, 9, 12 (N = 1e5) and
  // p = 9 (N = 1e6), random points on the sphere. 10 %: the repeats' spread, as kTie. Only p = 6
  // still takes a leaf from that sweep (p ≥ 9: the double layer's own points, the next test).
  EXPECT_EQ(expect_default_leaf_near_best<fmm::Stresslet>("perf/fmm/results/stresslet/leaf.jsonl", kTie, 800), 1u);
}

TEST(BackendChoice, TheStressletsDefaultLeafIsNearTheBestOnTheDoubleLayersOwnPoints) {
  // perf/bie/double_layer_leaf.jsonl (perf/bie/double_layer_leaf.cpp): edge-midpoint sources and
  // node targets of icosphere levels 5–7 on spheroids a/b = 1, 1.4, 2; leaves interleaved within
  // each sweep, so losses are ratios inside one sweep. The tree's depth moves in steps with the
  // leaf, and no leaf is best at every size (at level 5 a leaf of 2 000 wins, at level 7 it loses
  // 1.2–1.5×), so two bounds: within 10 % of the best (the repeats' spread, as kTie) at 81 920 and
  // 327 680 elements, where the FMM dominates a run (measured worst 1.09, p = 7), and within 60 %
  // at 20 480 (measured worst 1.56, p = 9). The leaf of 800 that p = 9 and 10 had lost 1.62× at
  // 81 920 elements (both orders) and fails the first bound.
  std::map<std::tuple<std::string, int, double, int, int>, std::map<int, double>> by;  // case → leaf → seconds
  for (const auto& r : read_jsonl("perf/bie/double_layer_leaf.jsonl")) {
    if (r["kernel"] != "stresslet") continue;
    by[{r["sweep"].get<std::string>(), r["level"].get<int>(), r["aspect"].get<double>(), r["order"].get<int>(),
        r["densities"].get<int>()}][r["leaf"].get<int>()] = r["wall_s"].get<double>();
  }
  int fine = 0;
  for (const auto& [key, times] : by) {
    const auto& [sweep, level, aspect, p, nd] = key;
    double best = INFINITY;
    for (const auto& [leaf, t] : times) best = std::min(best, t);
    const int leaf = fmm::default_leaf_size<fmm::Stresslet>(p);
    ASSERT_TRUE(times.count(leaf)) << sweep << ": leaf " << leaf << " not measured at p = " << p;
    const double loss = times.at(leaf) / best;
    fine += level >= 6;
    EXPECT_LE(loss, level >= 6 ? 1 + kTie : 1.6) << sweep << ", level " << level << ", a/b " << aspect << ", p = " << p
                                                 << ", " << nd << " densities: leaf " << leaf;
  }
  EXPECT_EQ(by.size(), 28u);  // levels 5–6: 2 × 3 shapes × 4 orders (6, 7, 9; 10 with 4 densities); level 7: 2 sweeps × 2 shapes, p = 9
  EXPECT_EQ(fine, 16);
}

TEST(BackendChoice, TheStokesletsDefaultLeafIsNearTheBestMeasuredAtTheBoundaryIntegralsSizes) {
  // perf/fmm/results/leaf_bie_stokeslet.jsonl (perf/fmm/leaf_bie.sh): leaves of 400–1 600 points at
  // p = 6–12 (200–1 300 at p = 4), 3 sources per target at the sizes of 20 480, 81 920 and 327 680
  // elements and sources = targets at N = 1e5. 25 %: single runs there scattered by up to ~20 %
  // (e.g. p = 10, leaf 1 000, 122 880 sources: 0.37 s between neighbours' 0.24–0.25 s); the
  // former leaf of 600 loses 1.5–3.3× and fails.
  EXPECT_EQ(expect_default_leaf_near_best<fmm::Stokeslet>("perf/fmm/results/leaf_bie_stokeslet.jsonl", 0.25), 28u);  // 4 sizes × 7 orders
}

TEST(BackendChoice, ASceneRequestIsHonouredWhateverTheSize) {
  std::string why;
  for (FarFieldKernel k : {FarFieldKernel::SingleLayer, FarFieldKernel::DoubleLayer}) {
    EXPECT_EQ(choose_backend(BackendRequest::Fmm, k, 10, 10, 1e-6, &why), FarFieldBackend::Fmm);
    EXPECT_NE(why.find("forced by the scene"), std::string::npos) << why;
    EXPECT_EQ(choose_backend(BackendRequest::Direct, k, 10'000'000, 1'000'000, 1e-6, &why), FarFieldBackend::Direct);
    EXPECT_NE(why.find("fluid.backend = \"direct\""), std::string::npos) << why;
  }
}

TEST(BackendChoice, SinglePrecisionPairsOnlyForTheSingleLayerFromTolerance1e5) {
  // 1e-5 leaves a 20× margin over the pairs' ~5e-7 (fmm/p2p_mixed.hpp): the direct sum's pairs and
  // the FMM's direct near field.
  EXPECT_EQ(uses_mixed_precision(1e-5), fmm::kMixedPrecisionDirectSum);
  EXPECT_EQ(uses_mixed_precision(1e-3), fmm::kMixedPrecisionDirectSum);
  EXPECT_FALSE(uses_mixed_precision(9.9e-6));
  std::string why;
  choose_backend(BackendRequest::Direct, FarFieldKernel::SingleLayer, 100, 100, 1e-4, &why);
  EXPECT_EQ(why.find("single precision") != std::string::npos, fmm::kMixedPrecisionDirectSum) << why;
  choose_backend(BackendRequest::Direct, FarFieldKernel::DoubleLayer, 100, 100, 1e-4, &why);
  EXPECT_EQ(why.find("single precision"), std::string::npos) << why;  // the double layer sums in double
}

TEST(BackendChoice, TheOperatorsCountOneSourcePerEdgeOrThreePerCurvedElement) {
  // Icosphere levels 2 and 5: 960 / 30 720 edge sources on flat facets, 3 Gauss points per element
  // on curved ones; the choice must be the one for that count (level 5 is decided by the
  // calibration, whichever way it falls).
  for (int level : {2, 5}) {
    const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, level);
    const Eigen::Index edges = mesh_edges(m).rows();
    EXPECT_EQ(edges * 2, 3 * m.num_elements());
    for (SurfaceGeometry g : {SurfaceGeometry::Flat, SurfaceGeometry::Curved}) {
      SingleLayerOptions o;
      o.geometry = g;
      const Eigen::Index sources = g == SurfaceGeometry::Flat ? edges : 3 * m.num_elements();
      EXPECT_EQ(far_field_source_count(o, m.num_elements(), edges), sources);
      const SingleLayer S(m.triangles, m.num_nodes(), o);
      EXPECT_EQ(S.far_field_sources(), sources);
      EXPECT_EQ(S.backend(), choose_backend(BackendRequest::Auto, FarFieldKernel::SingleLayer, sources, m.num_nodes(),
                                            o.tolerance, nullptr))
          << level;
      DoubleLayerOptions dl_o;
      dl_o.geometry = g;
      const DoubleLayer D(m.triangles, m.num_nodes(), dl_o);
      EXPECT_EQ(D.diagnostics().far_field_sources, sources);
      EXPECT_EQ(D.backend(), choose_backend(BackendRequest::Auto, FarFieldKernel::DoubleLayer, sources, m.num_nodes(),
                                            o.tolerance, nullptr))
          << level;
    }
  }
}
