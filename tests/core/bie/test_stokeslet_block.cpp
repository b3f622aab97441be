// The near field's eight-lane Stokeslet blocks (bie/stokeslet_block.hpp) against a scalar sum of
// the same pair formula in long double (stokeslet_reference.hpp): every lane range of a block, on the SIMD path this file
// is compiled for (AVX-512, AVX2 or scalar); empty lanes must add nothing, even at r = 0.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "capsflow/core/bie/stokeslet_block.hpp"
#include "capsflow/fmm/simd.hpp"
#include "stokeslet_reference.hpp"

using namespace capsflow;

namespace {

Vec3 reference(const Vec3& x, const StokesletBlock& b, int first, int count) {
  std::vector<std::pair<Vec3, Vec3>> terms;
  for (int j = first; j < first + count; ++j)
    terms.emplace_back(x - Vec3(b.y[0][j], b.y[1][j], b.y[2][j]), Vec3(b.f[0][j], b.f[1][j], b.f[2][j]));
  return test::stokeslet_reference_sum(terms);
}

}  // namespace

TEST(StokesletBlock, EveryLaneRangeMatchesTheLongDoubleSum) {
  std::mt19937 gen(11);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  StokesletBlock b;
  for (int j = 0; j < StokesletBlock::kLanes; ++j) b.set(j, Vec3(d(gen), d(gen), d(gen)), Vec3(d(gen), d(gen), d(gen)));
  const double x[3] = {2.5, -0.3, 0.7};
  const Vec3 xv(x[0], x[1], x[2]);
  using V = fmm::simd::VecD;
  for (int first = 0; first < StokesletBlock::kLanes; ++first)
    for (int count = 0; first + count <= StokesletBlock::kLanes; ++count) {
      V u[3] = {V(0.0), V(0.0), V(0.0)};
      b.accumulate(x, first, count, u);
      const Vec3 ref = reference(xv, b, first, count);
      // rsqrt with 2 Newton steps (or an exact division) and fused sums: a few ulp per term of size ~1.
      EXPECT_LE((lane_sum(u) - ref).norm(), 1e-14) << "lanes [" << first << ", " << first + count << ") on "
                                                   << fmm::simd::isa_name();
    }
}

TEST(StokesletBlock, EmptyLanesAddNothingEvenAtTheTarget) {
  StokesletBlock b;  // all lanes empty: y = 0, f = 0
  b.set(2, Vec3(2, 0, 0), Vec3(1, 0, 0));
  const double x[3] = {0, 0, 0};  // the target sits on every empty lane (r = 0)
  using V = fmm::simd::VecD;
  V u[3] = {V(0.0), V(0.0), V(0.0)};
  b.accumulate(x, 0, StokesletBlock::kLanes, u);
  const Vec3 s = lane_sum(u);
  // G(−2 e1) e1 = e1/2 + e1/2 = e1 exactly; the empty lanes must not turn it into NaN.
  EXPECT_NEAR(s.x(), 1.0, 1e-15);
  EXPECT_EQ(s.y(), 0.0);
  EXPECT_EQ(s.z(), 0.0);
}
