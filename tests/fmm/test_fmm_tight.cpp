// FMM against direct summation at the tightest tolerance the Stokeslet KIFMM reaches in double
// precision (label slow: order 10 operators). The 1e-9 case of issue 6 is NOT met (accuracy
// floor ~1.5e-8–3e-8, see calibration.hpp and perf/fmm/RESULTS.md); it is kept as a disabled
// test so that the gap stays visible: run with --gtest_also_run_disabled_tests.
#include <gtest/gtest.h>

#include <tuple>

#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/fmm.hpp"
#include "capsflow/fmm/stokeslet.hpp"
#include "points.hpp"

using namespace capsflow::fmm;
using namespace capsflow::fmm::testing;

namespace {
double error_at(const std::string& dist, bool same, double tol) {
  auto s = make_points(dist, 3000, 1);
  auto t = same ? s : make_points(dist, 1000, 2);
  const auto f = random_density(3 * 3000, 99);
  FmmOptions o;
  o.tolerance = tol;
  o.leaf_size = 48;
  o.cache_dir = CAPSFLOW_FMM_TEST_CACHE;
  Fmm<Stokeslet> fmm(o);
  fmm.setup(s.data(), 3000, t.data(), t.size() / 3);
  std::vector<double> u(t.size()), ref(t.size());
  fmm.evaluate(f.data(), u.data());
  direct_sum<Stokeslet>(s.data(), 3000, f.data(), t.data(), t.size() / 3, ref.data());
  return rel_l2(u, ref);
}
}  // namespace

class FmmTight : public ::testing::TestWithParam<std::tuple<std::string, bool>> {};

TEST_P(FmmTight, FiveTimesTenToTheMinusEight) {
  const auto [dist, same] = GetParam();
  EXPECT_LE(error_at(dist, same, 5e-8), 5e-8);  // requested tolerance (order 10)
}

TEST_P(FmmTight, DISABLED_OneEMinusNineNotReached) {
  const auto [dist, same] = GetParam();
  EXPECT_LE(error_at(dist, same, 1e-9), 1e-9);  // issue 6 asks for this; fails (floor ~2e-8)
}

INSTANTIATE_TEST_SUITE_P(Matrix, FmmTight,
                         ::testing::Combine(::testing::Values("sphere", "spheroid", "cube", "clustered"),
                                            ::testing::Bool()));
