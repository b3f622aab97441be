// FMM against direct summation (the oracle, itself pinned by test_kernels.cpp) for the Stokeslet
// and the stresslet (double layer): every distribution, sources = targets and sources != targets,
// requested tolerances; degenerate inputs; homogeneity and translation invariance; several
// densities per call; the Laplace kernel.
// Pass criterion (FMM3D's): relative L2 error over all targets <= requested tolerance.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <tuple>

#include "capsflow/fmm/laplace.hpp"
#include "capsflow/fmm/stokeslet.hpp"
#include "capsflow/fmm/stresslet.hpp"
#include "fmm_check.hpp"

using namespace capsflow::fmm;
using namespace capsflow::fmm::testing;

namespace {
// Runs body(K{}) with the kernel named by a test parameter.
template <class Body>
void with_kernel(const std::string& name, Body&& body) {
  if (name == "stokeslet") body(Stokeslet{});
  else if (name == "stresslet") body(Stresslet{});
  else FAIL() << "unknown kernel " << name;
}

// Bound on the relative error of one pair's value with the near field's one-Newton rsqrt: 1/|r|
// is within 6e-9 (simd.hpp), a pair term in 1/|r|^k within k·6e-9; the Stokeslet's terms go to
// k = 3 (bound 1e-8 as measured since its first tests), the stresslet's is k = 5 (3e-8).
template <class K>
constexpr double one_newton_bound() { return K::homogeneity == -2 ? 3e-8 : 1e-8; }

struct KernelName {
  template <class K>
  static std::string GetName(int) { return K::name; }
};
using Kernels = ::testing::Types<Stokeslet, Stresslet>;
}  // namespace

class FmmVsDirect : public ::testing::TestWithParam<std::tuple<std::string, std::string, bool, double>> {};

TEST_P(FmmVsDirect, RelativeL2BelowTolerance) {
  const auto [kernel, dist, same, tol] = GetParam();
  const std::size_t ns = 3000;
  auto s = make_points(dist, ns, 1);
  auto t = same ? s : make_points(dist, 1000, 2);
  with_kernel(kernel, [&](auto k) {
    using K = decltype(k);
    // leaf 48: several levels, so every operator (M2M, L2L, V, W, X) takes part
    const double err = fmm_error<K>(s, t, tol, 48);
    EXPECT_LE(err, tol) << kernel << " " << dist << (same ? " same" : " separate") << " p=" << order_for_tolerance<K>(tol);
  });
}

INSTANTIATE_TEST_SUITE_P(Matrix, FmmVsDirect,
                         ::testing::Combine(::testing::Values("stokeslet", "stresslet"),
                                            ::testing::Values("sphere", "spheroid", "cube", "clustered"),
                                            ::testing::Bool(), ::testing::Values(1e-3, 1e-6)));

// The near field's pairs in single precision (FmmOptions::single_precision_pairs, which the
// boundary integral takes from tolerance 1e-5): on every distribution, with sources = targets
// (coincident pairs skipped) or not, the FMM stays within the requested 1e-5 and departs from the
// same FMM with double pairs by the pairs' rounding only.
TEST(FmmSinglePrecisionPairs, StayWithinTheToleranceAndNearTheDoublePairs) {
  for (const char* dist : {"sphere", "spheroid", "cube", "clustered"})
    for (bool same : {true, false}) {
      auto s = make_points(dist, 3000, 1);
      auto t = same ? s : make_points(dist, 1000, 2);
      std::vector<double> us, ud;
      const double err = fmm_error<Stokeslet>(s, t, 1e-5, 48, &us, true);
      fmm_error<Stokeslet>(s, t, 1e-5, 48, &ud, false);
      EXPECT_LE(err, 1e-5) << dist << (same ? " same" : " separate");  // the FMM's own criterion
      // 1e-6: a tenth of the tolerance, five times the 0.9e-7–2.1e-7 measured on these clouds
      // (the pairs' rounding); a wrong lane, mask or shift errs by O(1)
      EXPECT_LT(rel_l2(us, ud), 1e-6) << dist << (same ? " same" : " separate");
    }
}

template <class K>
class FmmDegenerate : public ::testing::Test {};
TYPED_TEST_SUITE(FmmDegenerate, Kernels, KernelName);

TYPED_TEST(FmmDegenerate, EmptyAndSinglePoints) {
  using K = TypeParam;
  FmmOptions o;
  o.tolerance = 1e-3;
  Fmm<K> fmm(o, ops_for<K>(order_for_tolerance<K>(1e-3)));
  std::vector<double> u(3, 5.0);
  fmm.setup(nullptr, 0, nullptr, 0);
  fmm.evaluate(nullptr, nullptr);  // nothing to do, must not crash
  const double x[3] = {0.3, -0.2, 0.1}, f[6] = {1, 2, 3, -0.5, 0.7, 0.2};  // the first src_dim values
  fmm.setup(nullptr, 0, x, 1);
  fmm.evaluate(nullptr, u.data());
  for (double v : u) EXPECT_EQ(v, 0.0);  // no sources: exactly zero, overwritten
  fmm.setup(x, 1, x, 1);
  fmm.evaluate(f, u.data());
  for (double v : u) EXPECT_EQ(v, 0.0);  // the only pair is a self pair: skipped
  const double y[3] = {1.3, 0.8, -0.4};
  double ref[3];
  fmm.setup(x, 1, y, 1);
  fmm.evaluate(f, u.data());
  direct_sum<K>(x, 1, f, y, 1, ref);
  // one leaf: a pure direct sum, within the near field's one-Newton rsqrt of it
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(u[k], ref[k], one_newton_bound<K>() * std::abs(ref[k]) + 1e-16);
}

TYPED_TEST(FmmDegenerate, FewerPointsThanALeafAndAllInOneLeaf) {
  using K = TypeParam;
  auto s = make_points("cube", 50, 3);
  // 50 < default leaf: a pure direct sum, within the near field's one-Newton rsqrt of it
  EXPECT_LE(fmm_error<K>(s, s, 1e-6, 0), one_newton_bound<K>());
  auto s2 = make_points("sphere", 2000, 4);
  EXPECT_LE(fmm_error<K>(s2, s2, 1e-6, 5000), one_newton_bound<K>());  // one leaf holds everything; same bound
}

TYPED_TEST(FmmDegenerate, CoincidentPoints) {
  // 400 copies of one point plus 1600 others: the tree runs to its maximum depth there.
  auto s = make_points("sphere", 2000, 5);
  for (int i = 0; i < 400; ++i)
    for (int d = 0; d < 3; ++d) s[3 * i + d] = s[d];
  EXPECT_LE(fmm_error<TypeParam>(s, s, 1e-6, 48), 1e-6);  // requested tolerance
}

TYPED_TEST(FmmDegenerate, PointsOnAPlane) {
  auto s = make_points("cube", 3000, 6);
  for (std::size_t i = 0; i < 3000; ++i) s[3 * i + 2] = 0.25;
  auto t = make_points("cube", 800, 7);
  for (std::size_t i = 0; i < 800; ++i) t[3 * i + 2] = 0.25;
  EXPECT_LE(fmm_error<TypeParam>(s, t, 1e-6, 48), 1e-6);  // requested tolerance
}

template <class K>
class FmmInvariance : public ::testing::Test {};
TYPED_TEST_SUITE(FmmInvariance, Kernels, KernelName);

TYPED_TEST(FmmInvariance, ScalingByTenScalesByTenToTheDegree) {
  using K = TypeParam;
  auto s = make_points("spheroid", 3000, 8);
  std::vector<double> u1, u10;
  fmm_error<K>(s, s, 1e-6, 48, &u1);
  auto s10 = s;
  for (double& v : s10) v *= 10;
  fmm_error<K>(s10, s10, 1e-6, 48, &u10);
  for (double& v : u1) v *= std::pow(10.0, K::homogeneity);
  // both are within 1e-6 of exact sums that differ by exactly 10^degree (degree −1 for the
  // Stokeslet, −2 for the stresslet: pinned against closed forms in test_kernels.cpp)
  EXPECT_LE(rel_l2(u10, u1), 1e-6);
}

TYPED_TEST(FmmInvariance, Translation) {
  using K = TypeParam;
  auto s = make_points("clustered", 3000, 9);
  std::vector<double> u0, u1;
  fmm_error<K>(s, s, 1e-6, 48, &u0);
  auto st = s;
  for (std::size_t i = 0; i < 3000; ++i) { st[3 * i] += 100; st[3 * i + 1] -= 50; st[3 * i + 2] += 3; }
  const double err = fmm_error<K>(st, st, 1e-6, 48, &u1);
  // 1e-6 is the requested tolerance; the shift by 100 costs ~1e-14·100 relative in coordinates
  EXPECT_LE(err, 1e-6);
  EXPECT_LE(rel_l2(u1, u0), 2e-6);  // each within 1e-6 of the same exact answer
}

template <class K>
class FmmApi : public ::testing::Test {};
TYPED_TEST_SUITE(FmmApi, Kernels, KernelName);

TYPED_TEST(FmmApi, SeveralDensitiesPerCallAndRepeatedEvaluation) {
  using K = TypeParam;
  constexpr std::size_t SD = K::src_dim;
  auto s = make_points("sphere", 2500, 10), t = make_points("sphere", 700, 11);
  FmmOptions o;
  o.tolerance = 1e-6;
  o.leaf_size = 48;
  Fmm<K> fmm(o, ops_for<K>(order_for_tolerance<K>(1e-6)));
  fmm.setup(s.data(), 2500, t.data(), 700);
  const auto f = random_density(2 * SD * 2500, 12);
  std::vector<double> both(2 * 3 * 700), one(3 * 700), two(3 * 700);
  fmm.evaluate(f.data(), both.data(), 2);
  fmm.evaluate(f.data(), one.data());
  fmm.evaluate(f.data() + SD * 2500, two.data());
  std::vector<double> b1(both.begin(), both.begin() + 2100), b2(both.begin() + 2100, both.end());
  // same operations in the same order per target: equal to rounding (1e-14 relative)
  EXPECT_LE(rel_l2(b1, one), 1e-14);
  EXPECT_LE(rel_l2(b2, two), 1e-14);
  std::vector<double> ref(3 * 700);
  direct_sum<K>(s.data(), 2500, f.data() + SD * 2500, t.data(), 700, ref.data());
  EXPECT_LE(rel_l2(b2, ref), 1e-6);  // requested tolerance
}

TEST(FmmLaplace, SecondKernelThroughTheSameMachinery) {
  for (const char* dist : {"sphere", "clustered"}) {
    auto s = make_points(dist, 3000, 13), t = make_points(dist, 900, 14);
    EXPECT_LE(fmm_error<Laplace>(s, t, 1e-6, 48), 1e-6) << dist;  // requested tolerance
  }
}

class FmmMultiDensity : public ::testing::TestWithParam<std::tuple<std::string, double, int, bool>> {};

TEST_P(FmmMultiDensity, OneCallEqualsSeparateCalls) {
  // k densities in one call share every pass (P2P distances, operator GEMMs, M2L kernel blocks);
  // each density must still get the answer of its own single-density call.
  const auto [kernel, tol, k, same] = GetParam();
  const std::size_t ns = 3000, nt = same ? ns : 900;
  auto s = make_points("clustered", ns, 31);
  auto t = same ? s : make_points("clustered", nt, 32);
  with_kernel(kernel, [&](auto kern) {
    using K = decltype(kern);
    constexpr std::size_t SD = K::src_dim;
    FmmOptions o;
    o.tolerance = tol;
    o.leaf_size = 48;  // several levels: M2M, L2L, V, W and X lists all take part
    Fmm<K> fmm(o, ops_for<K>(order_for_tolerance<K>(tol)));
    fmm.setup(s.data(), ns, t.data(), nt);
    ASSERT_GT(fmm.tree().W.item.size() + fmm.tree().X.item.size(), 0u);
    const auto f = random_density(SD * ns * k, 33);
    std::vector<double> multi(3 * nt * k, 7.0);
    fmm.evaluate(f.data(), multi.data(), k);
    for (int d = 0; d < k; ++d) {
      std::vector<double> one(3 * nt), part(multi.begin() + 3 * nt * d, multi.begin() + 3 * nt * (d + 1));
      fmm.evaluate(f.data() + SD * ns * d, one.data());
      // 1e-13: the same operations per density, only the blocking of the shared GEMMs may change
      // the rounding (round-off agreement is asked)
      EXPECT_LE(rel_l2(part, one), 1e-13) << "density " << d << " of " << k;
      if (d == k - 1) {  // and the shared pass is still an FMM: the last density against direct
        std::vector<double> ref(3 * nt);
        direct_sum<K>(s.data(), ns, f.data() + SD * ns * d, t.data(), nt, ref.data());
        // The requested tolerance: the shared pass is still the FMM at the calibrated order (an
        // indexing slip between densities gives O(1) errors).
        EXPECT_LE(rel_l2(part, ref), tol);
      }
    }
  });
}

// k = 3 (one shared group), k = 6 (groups of 4 + 2); 1e-6 uses the one-Newton near field, 1e-8
// the exact one; each k and tolerance once with sources = targets and once without; the
// stresslet (whose upward densities have 4 components, downward 3) in two cases, 2e-7 so that it
// runs at p = 11 like the Stokeslet's 1e-8 (p = 12 operators would take minutes on a cold cache)
INSTANTIATE_TEST_SUITE_P(Counts, FmmMultiDensity,
                         ::testing::Values(std::make_tuple("stokeslet", 1e-6, 3, true),
                                           std::make_tuple("stokeslet", 1e-6, 6, false),
                                           std::make_tuple("stokeslet", 1e-8, 3, false),
                                           std::make_tuple("stokeslet", 1e-8, 6, true),
                                           std::make_tuple("stresslet", 1e-6, 6, false),
                                           std::make_tuple("stresslet", 2e-7, 3, true)));

namespace {
// Relative L2 error of the stresslet FMM at tolerance tol (its calibrated order, leaf 48: several
// levels, as in FmmVsDirect) against the direct sum, sources = targets = s (3000 points).
double stresslet_error_on_surface(const std::vector<double>& s, const std::vector<double>& d, double tol) {
  FmmOptions o;
  o.tolerance = tol;
  o.leaf_size = 48;
  Fmm<Stresslet> fmm(o, ops_for<Stresslet>(order_for_tolerance<Stresslet>(tol)));
  fmm.setup(s.data(), 3000, s.data(), 3000);
  std::vector<double> u(9000), ref(9000);
  fmm.evaluate(d.data(), u.data());
  direct_sum<Stresslet>(s.data(), 3000, d.data(), s.data(), 3000, ref.data());
  return rel_l2(u, ref);
}
}  // namespace

TEST(FmmStresslet, SmoothSurfaceDoubleLayer) {
  // The boundary integral's use: sources = targets on a closed surface, f = w·u(y) with a smooth u
  // and n the outward normal (points.hpp, surface_double_layer). Unlike random densities the sum
  // carries the cancellations of a closed surface (for constant u: u inside, 0 outside), so the
  // relative error is taken against a smaller, smoother answer.
  for (const char* dist : {"sphere", "spheroid"})
    for (double tol : {1e-3, 1e-6}) {
      const auto s = make_points(dist, 3000, 21);
      EXPECT_LE(stresslet_error_on_surface(s, surface_double_layer(dist, s), tol), tol)
          << dist << " tol " << tol;  // the requested tolerance
    }
}

TEST(FmmStresslet, RandomDensityWithSurfaceNormals) {
  // Random f with the outward unit normals on a closed surface (points.hpp,
  // random_surface_double_layer), sources = targets, small leaves: the case that missed 1e-6 at
  // p = 9 (relative L2 1.0e-6–1.3e-6 on the sphere, N = 3000, leaf 48), and with it the stresslet's
  // calibration (calibration.hpp). On the sphere r·n = −|r|²/2, so each pair is a 1/|r| term and
  // the sum is far smaller than its 1/|r|² terms: the hardest of the calibrated densities.
  for (const char* dist : {"sphere", "spheroid"})
    for (double tol : {1e-3, 1e-6})
      for (unsigned seed : {1u, 5u, 9u}) {
        const auto s = make_points(dist, 3000, seed);
        // Half the requested tolerance: the calibration keeps a factor ~2 over the worst error it
        // measured at each order (calibration.hpp; at 1e-6, p = 10: 3.1e-7 worst here).
        EXPECT_LE(stresslet_error_on_surface(s, random_surface_double_layer(dist, s, seed + 1), tol), 0.5 * tol)
            << dist << " tol " << tol << " seed " << seed << " p = " << order_for_tolerance<Stresslet>(tol);
      }
}
