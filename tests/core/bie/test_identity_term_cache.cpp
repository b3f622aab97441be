// The cache of the double layer's D̃[1] between refreshes (identity_term_cache.hpp,
// docs/boundary-integral.md §4.7.5) on its own, fed values of D̃[1] whose reuse has a known answer:
// a drift quadratic in a parameter t on a fixed surface (the extrapolation along three refreshes
// is exact), a rigid motion (the stored error turns with the local frames), and a drift of a
// chosen size at one sample (the refresh is called exactly above the threshold). The operator
// itself (DoubleLayerIdentityReuse.*, test_corner_double_layer.cpp) is tested against full passes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>
#include <vector>

#include "capsflow/core/bie/corner_double_layer.hpp"
#include "capsflow/core/bie/identity_term_cache.hpp"
#include "capsflow/core/mesh/generation.hpp"

using namespace capsflow;

namespace {

// An a/b = 1.5 spheroid of icosphere nodes (no symmetry hides an error); at level 3 its 642 nodes
// are all sampled (kSamples = 512: every node), at level 4 one node in five.
struct Surface {
  SurfaceMesh mesh;
  Points x;
  std::vector<int> order;  // the sample's order: the nodes' numbering
};
Surface spheroid(int level) {
  Surface s{make_sphere_mesh(BaseSolid::Icosahedron, level), {}, {}};
  s.x = s.mesh.vertices;
  s.x.col(2) *= 1.5;
  s.order.resize(static_cast<size_t>(s.x.rows()));
  std::iota(s.order.begin(), s.order.end(), 0);
  return s;
}

// Random symmetric matrices of Frobenius norm about `size`, one per node.
std::vector<Mat3> random_symmetric(Eigen::Index n, double size, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<Mat3> m(static_cast<size_t>(n));
  for (Mat3& a : m) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j <= i; ++j) a(i, j) = a(j, i) = size * uniform(gen) / 2.5;
  }
  return m;
}

// The operator's diagonal ½ I − D̃[1] per node, from D̃[1].
std::vector<double> diagonal_of(const std::vector<Mat3>& D) {
  std::vector<double> d(6 * D.size());
  for (size_t i = 0; i < D.size(); ++i) store_symmetric(0.5 * Mat3::Identity() - D[i], &d[6 * i]);
  return d;
}

// D̃[1] at the cache's samples, in their order.
std::vector<Mat3> at_samples(const IdentityTermCache& cache, const std::vector<Mat3>& D) {
  std::vector<Mat3> s;
  for (const int i : cache.samples()) s.push_back(D[static_cast<size_t>(i)]);
  return s;
}

// The largest Frobenius difference between the cache's reused D̃[1] and `expected` over all nodes.
double reuse_error(const IdentityTermCache& cache, const std::vector<Mat3>& expected) {
  std::vector<double> d(6 * expected.size());
  cache.reuse(d.data());
  double e = 0;
  for (size_t i = 0; i < expected.size(); ++i)
    e = std::max(e, (0.5 * Mat3::Identity() - symmetric_matrix(&d[6 * i]) - expected[i]).norm());
  return e;
}

}  // namespace

// On a fixed surface (C and the frames do not change) D̃[1](t) = ½ I + A + t B + t² Q per node: E
// in the local frames is quadratic in t as well, so after refreshes at t = 0, 1, 2 the fit along
// the two secants is exact at t = 3 — s = 2, s2 = −1 (E(3) = 3 E(2) − 3 E(1) + E(0)) — and so is
// the reuse at every node, sampled or not (level 4: four nodes in five are not). Tolerance 1e-14:
// the round-off of E (~1e-16 of |D̃[1]| ≈ 1, through the frames) amplified by the coefficients'
// sizes (|1 + s| + |s − s2| + |s2| = 7); measured 7.9e-16. The line through the last two refreshes
// alone would err by |Q| (1e-5), the quadratic's own term.
TEST(IdentityTermCache, ExtrapolatesAQuadraticDriftExactly) {
  const Surface s = spheroid(4);
  const Eigen::Index n = s.x.rows();
  const std::vector<Mat3> A = random_symmetric(n, 1e-3, 1), B = random_symmetric(n, 1e-4, 2), Q = random_symmetric(n, 1e-5, 3);
  auto D = [&](double t) {
    std::vector<Mat3> d(static_cast<size_t>(n));
    for (size_t i = 0; i < d.size(); ++i) d[i] = 0.5 * Mat3::Identity() + A[i] + t * B[i] + t * t * Q[i];
    return d;
  };
  IdentityTermCache cache(s.mesh.triangles, n, s.order, 1e-6, 1);
  ASSERT_LT(cache.samples().size(), static_cast<size_t>(n) / 2);  // most nodes are not sampled
  for (int t = 0; t <= 2; ++t) {
    cache.set_surface(s.x);
    EXPECT_EQ(cache.forced_refresh(true, false), t == 0);  // the first set-up has nothing to reuse
    bool called = false;
    if (t > 0) called = cache.measure(at_samples(cache, D(t)), true);
    EXPECT_EQ(called, t > 0);  // E moved by ~1e-4 against a threshold of 1.25e-7
    cache.refresh(diagonal_of(D(t)).data(), true, called);
  }
  cache.set_surface(s.x);
  ASSERT_FALSE(cache.forced_refresh(true, false));
  EXPECT_FALSE(cache.measure(at_samples(cache, D(3)), true));
  const IdentityTermStats st = cache.stats();
  const double error = reuse_error(cache, D(3));
  std::printf("quadratic drift: s = %.15f, sampled drift %.2e, reuse error %.2e\n", st.extrapolation, st.sampled_drift, error);
  EXPECT_NEAR(st.extrapolation, 2.0, 1e-9);  // the 2×2 normal equations' round-off on exact data
  EXPECT_LT(st.sampled_drift, 1e-14);
  EXPECT_LT(error, 1e-14);
  EXPECT_EQ(st.refreshes, 3);
}

// Two refreshes, t = 0 and 1, of a drift linear in t: the line through them is exact up to the
// clamp of s at 3 (kExtrapolationRange). At t = 2.5 (s = 1.5) the reuse is exact; at t = 5 (s
// would be 4) it stops at t = 4 and errs by B itself: the sampled drift is max_i ‖B_i‖ (the
// Frobenius norm does not see the frames). Tolerances as above: round-off of E, coefficients ≤ 4.
TEST(IdentityTermCache, ExtrapolatesALinearDriftAsFarAsItsClamp) {
  const Surface s = spheroid(3);
  const Eigen::Index n = s.x.rows();
  const std::vector<Mat3> A = random_symmetric(n, 1e-3, 4), B = random_symmetric(n, 1e-4, 5);
  auto D = [&](double t) {
    std::vector<Mat3> d(static_cast<size_t>(n));
    for (size_t i = 0; i < d.size(); ++i) d[i] = 0.5 * Mat3::Identity() + A[i] + t * B[i];
    return d;
  };
  double largest_B = 0;
  for (const Mat3& b : B) largest_B = std::max(largest_B, b.norm());
  IdentityTermCache cache(s.mesh.triangles, n, s.order, 1e-6, 1);
  ASSERT_EQ(cache.samples().size(), static_cast<size_t>(n));  // every node sampled at this level
  for (int t = 0; t <= 1; ++t) {
    cache.set_surface(s.x);
    cache.refresh(diagonal_of(D(t)).data(), true, false);
  }
  cache.set_surface(s.x);
  EXPECT_FALSE(cache.measure(at_samples(cache, D(2.5)), true));
  EXPECT_NEAR(cache.stats().extrapolation, 1.5, 1e-9);
  EXPECT_LT(reuse_error(cache, D(2.5)), 1e-14);
  cache.set_surface(s.x);
  EXPECT_TRUE(cache.measure(at_samples(cache, D(5)), true));  // 1e-4 against 1.25e-7
  EXPECT_EQ(cache.stats().extrapolation, 3.0);
  EXPECT_NEAR(cache.stats().sampled_drift, largest_B, 1e-14);
  EXPECT_NEAR(reuse_error(cache, D(5)), largest_B, 1e-14);
}

// A rigid motion y = Q x + b: the polyhedron's corner values turn with it (C(y)_i = Q C(x)_i Qᵀ),
// and so does the exact D̃[1] of the turned surface, D̃[1](y)_i = Q D̃[1](x)_i Qᵀ; the error term
// stored in the local frames must follow. D̃[1](x) = C(x) + G with G a random symmetric matrix of
// size 1e-3 per node (not a quadrature error: any stored term must turn). The sample sees no
// drift, the motion is no jump, and the reuse equals the turned D̃[1] to round-off (1e-14: the
// frames and C recomputed on the moved nodes, whose coordinates are now ~2 where they were ~1;
// measured 2.8e-15); kept in the global frame it would err by |G − Q G Qᵀ| ~ 1e-3.
TEST(IdentityTermCache, TheStoredErrorTurnsWithTheSurface) {
  const Surface s = spheroid(3);
  const Eigen::Index n = s.x.rows();
  const CornerFans fans(s.mesh.triangles, n);
  const std::vector<Mat3> G = random_symmetric(n, 1e-3, 6);
  std::vector<Mat3> before(static_cast<size_t>(n)), after(static_cast<size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) before[static_cast<size_t>(i)] = corner_double_layer(s.x, i, fans) + G[static_cast<size_t>(i)];
  const Mat3 Q = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  Points y = s.x * Q.transpose();
  y.rowwise() += Eigen::RowVector3d(0.3, -1, 2);
  for (size_t i = 0; i < after.size(); ++i) after[i] = Q * before[i] * Q.transpose();

  IdentityTermCache cache(s.mesh.triangles, n, s.order, 1e-6, 1);
  cache.set_surface(s.x);
  cache.refresh(diagonal_of(before).data(), true, false);
  cache.set_surface(y);
  EXPECT_FALSE(cache.forced_refresh(true, false));  // the corner values in their frames did not move
  EXPECT_FALSE(cache.measure(at_samples(cache, after), true));
  const double error = reuse_error(cache, after);
  std::printf("rigid motion: sampled drift %.2e, reuse error %.2e\n", cache.stats().sampled_drift, error);
  EXPECT_LT(cache.stats().sampled_drift, 1e-14);
  EXPECT_LT(error, 1e-14);
  // The test sees the turn: the stored term left unturned would be this far off.
  double unturned = 0;
  for (size_t i = 0; i < after.size(); ++i) unturned = std::max(unturned, (G[i] - Q * G[i] * Q.transpose()).norm());
  EXPECT_GT(unturned, 1e-4);
}

// After one refresh (no extrapolation: s = 0), a drift of size δ at one sample and none elsewhere:
// the sampled drift is δ (the Frobenius norm of a symmetric perturbation of norm δ, in any frame),
// and a trajectory set-up refreshes exactly when δ exceeds kSampledDriftShare ×
// kIdentityDriftShare × tolerance = 1.25e-4 at tolerance 1e-3. δ within 1e-6 of the threshold on
// either side: the drift's round-off (~1e-16 of |D̃[1]| ≈ 1) is a millionth of that margin. Off
// the trajectory a set-up never refreshes, and only trajectory reuses count in max_reused_drift.
TEST(IdentityTermCache, RefreshesExactlyWhenTheSampledDriftPassesTheThreshold) {
  const Surface s = spheroid(3);
  const Eigen::Index n = s.x.rows();
  const double tolerance = 1e-3;
  const double threshold = IdentityTermCache::kSampledDriftShare * IdentityTermCache::kIdentityDriftShare * tolerance;
  ASSERT_DOUBLE_EQ(threshold, 1.25e-4);
  const std::vector<Mat3> G = random_symmetric(n, 1e-3, 7), M = random_symmetric(1, 1.0, 8);
  std::vector<Mat3> D(static_cast<size_t>(n));
  for (size_t i = 0; i < D.size(); ++i) D[i] = 0.5 * Mat3::Identity() + G[i];
  IdentityTermCache cache(s.mesh.triangles, n, s.order, tolerance, 1);
  cache.set_surface(s.x);
  cache.refresh(diagonal_of(D).data(), true, false);
  const Mat3 unit = M[0] / M[0].norm();
  auto drifted = [&](double delta) {
    std::vector<Mat3> e = at_samples(cache, D);
    e[e.size() / 2] += delta * unit;
    return e;
  };
  cache.set_surface(s.x);
  ASSERT_FALSE(cache.forced_refresh(true, false));
  EXPECT_FALSE(cache.measure(drifted(threshold * (1 - 1e-6)), true));
  EXPECT_NEAR(cache.stats().sampled_drift, threshold * (1 - 1e-6), 1e-15);
  EXPECT_NEAR(cache.stats().max_reused_drift, threshold * (1 - 1e-6), 1e-15);
  cache.set_surface(s.x);
  EXPECT_FALSE(cache.measure(drifted(2 * threshold), false));  // off the trajectory: never
  EXPECT_NEAR(cache.stats().max_reused_drift, threshold * (1 - 1e-6), 1e-15);  // not counted
  cache.set_surface(s.x);
  EXPECT_TRUE(cache.measure(drifted(threshold * (1 + 1e-6)), true));
  EXPECT_EQ(cache.stats().extrapolation, 0.0);  // a single refresh: nothing to extrapolate along
}

// The forced refreshes: the first set-up, a checked surface on the trajectory (not off it), and a
// corner value that jumped between the samples — one node whose fan holds no sampled node, pushed
// out by a tenth of an edge (level 4) — while a 5 % stretch of the whole surface, which moves the
// sampled corners as much as the others, is left to the sample.
TEST(IdentityTermCache, ForcesARefreshFirstOnACheckedSurfaceAndAfterAJumpBetweenTheSamples) {
  const Surface s = spheroid(4);
  const Eigen::Index n = s.x.rows();
  const std::vector<Mat3> D(static_cast<size_t>(n), 0.5 * Mat3::Identity());
  IdentityTermCache cache(s.mesh.triangles, n, s.order, 1e-6, 1);
  cache.set_surface(s.x);
  EXPECT_TRUE(cache.forced_refresh(true, false));
  EXPECT_TRUE(cache.forced_refresh(false, false));
  cache.refresh(diagonal_of(D).data(), true, false);
  cache.set_surface(s.x);
  EXPECT_FALSE(cache.forced_refresh(true, false));
  EXPECT_TRUE(cache.forced_refresh(true, true));    // verify_every: the check is of the full pass
  EXPECT_FALSE(cache.forced_refresh(false, true));  // off the trajectory the run is not moved
  std::vector<char> near_a_sample(static_cast<size_t>(n), 0);
  for (const int j : cache.samples())
    for (Eigen::Index t = 0; t < s.mesh.triangles.rows(); ++t)
      if ((s.mesh.triangles.row(t).array() == j).any())
        for (int c = 0; c < 3; ++c) near_a_sample[static_cast<size_t>(s.mesh.triangles(t, c))] = 1;
  Eigen::Index bumped = 0;
  while (near_a_sample[static_cast<size_t>(bumped)]) ++bumped;
  ASSERT_LT(bumped, n);
  Points y = s.x;
  y.row(bumped) *= 1.003;  // ~a tenth of an edge (~0.04 at level 4)
  cache.set_surface(y);
  EXPECT_TRUE(cache.forced_refresh(true, false));
  Points stretched = s.x;
  stretched.col(0) *= 1.05;
  cache.set_surface(stretched);
  EXPECT_FALSE(cache.forced_refresh(true, false));
}
