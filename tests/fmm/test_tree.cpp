// Tree invariants and list completeness. The list test uses a counting kernel (every source
// contributes exactly 1 to every target it does not coincide with, through every FMM operator),
// so a missing or doubly counted interaction shows up as an integer error, independently of the
// FMM's approximation accuracy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <tuple>
#include <vector>

#include "capsflow/fmm/fmm.hpp"
#include "capsflow/fmm/key_sort.hpp"
#include "points.hpp"

using namespace capsflow::fmm;
using namespace capsflow::fmm::testing;

namespace {
// Constant kernel: K(r) = 1 for r != 0, 0 for r = 0; homogeneity 0 (scale invariant).
// The check-to-equivalent operators of a constant kernel are exact (rank one), so the FMM sum
// equals the count up to rounding.
struct CountingKernel {
  static constexpr int src_dim = 1, trg_dim = 1, homogeneity = 0;
  static constexpr const char* name = "test_counting";
  static constexpr double scale() { return 1.0; }
  template <class V>
  static void eval(V (&u)[1], const V (&r)[3], const V& rinv, const V (&q)[1]) {
    const V r2 = simd::fma(r[0], r[0], simd::fma(r[1], r[1], r[2] * r[2]));
    u[0] = simd::fma(r2 * rinv * rinv, q[0], u[0]);  // 1 (to rounding) or exactly 0 at r = 0
  }
};

std::vector<double> expected_counts(const std::vector<double>& s, const std::vector<double>& t) {
  std::map<std::tuple<double, double, double>, int> mult;
  for (std::size_t j = 0; j < s.size() / 3; ++j) ++mult[{s[3 * j], s[3 * j + 1], s[3 * j + 2]}];
  std::vector<double> c(t.size() / 3);
  for (std::size_t i = 0; i < c.size(); ++i) {
    auto it = mult.find({t[3 * i], t[3 * i + 1], t[3 * i + 2]});
    c[i] = static_cast<double>(s.size() / 3) - (it == mult.end() ? 0 : it->second);
  }
  return c;
}

std::string cache_dir() { return std::string(CAPSFLOW_FMM_TEST_CACHE); }
}  // namespace

TEST(Tree, Invariants) {
  auto s = make_points("clustered", 3000, 1), t = make_points("sphere", 1000, 2);
  Tree T;
  const int leaf = 16;
  T.build(s.data(), 3000, t.data(), 1000, leaf, 2);
  ASSERT_GT(T.levels(), 3);
  std::vector<int> src_seen(3000, 0), trg_seen(1000, 0);
  for (std::size_t n = 0; n < T.nodes.size(); ++n) {
    const Node& B = T.nodes[n];
    // levels stored contiguously
    EXPECT_GE(n, T.level_begin[B.level]);
    EXPECT_LT(n, T.level_begin[B.level + 1]);
    if (B.parent >= 0) {
      const Node& P = T.nodes[B.parent];
      EXPECT_EQ(P.level + 1, B.level);
      EXPECT_EQ(P.child[B.octant], static_cast<int>(n));
      EXPECT_TRUE(B.sb >= P.sb && B.se <= P.se && B.tb >= P.tb && B.te <= P.te);
    }
    EXPECT_TRUE(B.nsrc() + B.ntrg() > 0);  // empty boxes are discarded
    if (!B.leaf) {
      // children partition the parent's ranges
      std::size_t ns = 0, nt = 0;
      for (int c : B.child)
        if (c >= 0) { ns += T.nodes[c].nsrc(); nt += T.nodes[c].ntrg(); }
      EXPECT_EQ(ns, B.nsrc());
      EXPECT_EQ(nt, B.ntrg());
      continue;
    }
    if (B.level < Tree::kMaxLevel) {
      EXPECT_LE(B.nsrc(), static_cast<std::size_t>(leaf));
      EXPECT_LE(B.ntrg(), static_cast<std::size_t>(leaf));
    }
    double c[3];
    T.center(static_cast<int>(n), c);
    const double r = Tree::half_width(B.level) * (1 + 1e-12);  // points lie in their leaf box
    for (std::size_t i = B.sb; i < B.se; ++i) {
      ++src_seen[T.src_perm[i]];
      EXPECT_LE(std::abs(T.sx[i] - c[0]), r);
      EXPECT_LE(std::abs(T.sy[i] - c[1]), r);
      EXPECT_LE(std::abs(T.sz[i] - c[2]), r);
    }
    for (std::size_t i = B.tb; i < B.te; ++i) {
      ++trg_seen[T.trg_perm[i]];
      EXPECT_LE(std::abs(T.tx[i] - c[0]), r);
    }
  }
  for (int v : src_seen) EXPECT_EQ(v, 1);  // every source in exactly one leaf
  for (int v : trg_seen) EXPECT_EQ(v, 1);
  // V-list members are same-level, not adjacent, children of the parent's colleagues
  for (std::size_t n = 0; n < T.nodes.size(); ++n)
    for (std::size_t v = T.V.begin[n]; v < T.V.begin[n + 1]; ++v) {
      const int a = T.V.item[v];
      EXPECT_EQ(T.nodes[a].level, T.nodes[n].level);
      EXPECT_FALSE(T.adjacent(a, static_cast<int>(n)));
      EXPECT_TRUE(T.adjacent(T.nodes[a].parent, T.nodes[n].parent));
      EXPECT_GE(T.v_offset[v], 0);
    }
}

class CountingLists : public ::testing::TestWithParam<std::tuple<std::string, bool, int>> {};

TEST_P(CountingLists, EveryTargetGetsEverySourceOnce) {
  const auto [dist, same, leaf] = GetParam();
  const std::size_t ns = 3000, nt = same ? ns : 1200;
  auto s = make_points(dist, ns, 11);
  auto t = same ? s : make_points(dist == "sphere" ? "clustered" : "sphere", nt, 12);
  if (!same)
    for (int k = 0; k < 50; ++k)  // some targets coincide with sources
      for (int d = 0; d < 3; ++d) t[3 * k + d] = s[3 * (7 * k) + d];
  std::vector<double> q(ns, 1.0), u(nt);
  FmmOptions o;
  o.order = 4;
  o.leaf_size = leaf;
  o.exact_near_field = true;  // count to rounding, not to the fast rsqrt's 6e-9 per pair
  o.cache_dir = cache_dir();
  Fmm<CountingKernel> fmm(o);
  fmm.setup(s.data(), ns, t.data(), nt);
  fmm.evaluate(q.data(), u.data());
  const auto expect = expected_counts(s, t);
  double worst = 0;
  for (std::size_t i = 0; i < nt; ++i) worst = std::max(worst, std::abs(u[i] - expect[i]));
  // 1e-6: operator rounding is ~1e-12 relative of N = 3000; one missing or doubled pair is >= 1.
  EXPECT_LT(worst, 1e-6);
  // the case must exercise the far field, not only direct sums
  EXPECT_GT(fmm.tree().V.item.size(), 0u);
  // three densities in one call (one shared pass): density d = (d + 1)·q must count (d + 1)·N
  // through every list; an indexing slip between densities shows up as an integer error
  std::vector<double> q3(3 * ns), u3(3 * nt);
  for (int d = 0; d < 3; ++d)
    for (std::size_t j = 0; j < ns; ++j) q3[d * ns + j] = d + 1.0;
  fmm.evaluate(q3.data(), u3.data(), 3);
  double worst3 = 0;
  for (int d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < nt; ++i) worst3 = std::max(worst3, std::abs(u3[d * nt + i] - (d + 1.0) * expect[i]));
  EXPECT_LT(worst3, 3e-6);  // same bound as above, counts up to 3x larger
}

INSTANTIATE_TEST_SUITE_P(
    Distributions, CountingLists,
    ::testing::Combine(::testing::Values("sphere", "clustered", "cube"), ::testing::Bool(),
                       ::testing::Values(8, 40)));

TEST(CountingLists, AdaptiveTreeExercisesWAndXLists) {
  // strongly clustered sources with uniform targets: coarse leaves next to fine ones
  auto s = make_points("clustered", 4000, 21), t = make_points("cube", 1500, 22);
  std::vector<double> q(4000, 1.0), u(1500);
  FmmOptions o;
  o.order = 4;
  o.leaf_size = 10;
  o.exact_near_field = true;
  o.cache_dir = cache_dir();
  Fmm<CountingKernel> fmm(o);
  fmm.setup(s.data(), 4000, t.data(), 1500);
  EXPECT_GT(fmm.tree().W.item.size(), 0u);
  EXPECT_GT(fmm.tree().X.item.size(), 0u);
  fmm.evaluate(q.data(), u.data());
  const auto expect = expected_counts(s, t);
  double worst = 0;
  for (std::size_t i = 0; i < 1500; ++i) worst = std::max(worst, std::abs(u[i] - expect[i]));
  EXPECT_LT(worst, 1e-6);  // same reason as above
}

// The tree's radix sort (key_sort.hpp) gives std::sort's order of (key, index) pairs whose indices
// are distinct and ascending: keys that share high bits, that differ in every bit, and repeated keys.
TEST(KeySort, EqualsTheComparisonSortOfKeyIndexPairs) {
  std::uint64_t state = 0x9e3779b97f4a7c15ULL;
  auto next = [&] {  // xorshift64*
    state ^= state >> 12;
    state ^= state << 25;
    state ^= state >> 27;
    return state * 0x2545f4914f6cdd1dULL;
  };
  for (const std::uint64_t mask : {~std::uint64_t{0}, std::uint64_t{0x7fff}, std::uint64_t{0x3}}) {
    for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{1000}, std::size_t{50000}}) {
      const std::uint64_t high = next() & ~mask;  // bits every key shares
      std::vector<KeyIndex> kp(n), scratch;
      for (std::size_t i = 0; i < n; ++i) kp[i] = {high | (next() & mask), i};
      std::vector<KeyIndex> expected = kp;
      std::sort(expected.begin(), expected.end());
      sort_by_key(kp, scratch);
      EXPECT_TRUE(kp == expected) << "mask " << mask << ", n " << n;
    }
  }
}
