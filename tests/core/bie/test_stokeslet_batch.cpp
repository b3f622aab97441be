// The near-field Stokeslet batch (bie/stokeslet_batch.hpp) against a scalar sum of the same
// pair formula in long double: the SIMD path (AVX-512, AVX2 or scalar, whichever this file is
// compiled for) must give full double accuracy, padded lanes must add nothing, and r = 0 must be
// skipped (fmm::Stokeslet's convention).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "capsflow/core/bie/stokeslet_batch.hpp"
#include "capsflow/fmm/simd.hpp"
#include "stokeslet_reference.hpp"

using namespace capsflow;
using capsflow::test::stokeslet_reference_sum;

TEST(StokesletBatch, MatchesLongDoubleReferenceForEverySizeModuloTheVectorWidth) {
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  StokesletBatch batch;
  for (int n : {0, 1, 3, 7, 8, 9, 15, 16, 17, 100, 1031}) {  // every remainder of widths 1, 4, 8
    batch.clear();
    std::vector<std::pair<Vec3, Vec3>> terms;
    for (int j = 0; j < n; ++j) {
      const Vec3 r(d(gen), d(gen), d(gen)), f(d(gen), d(gen), d(gen));
      terms.emplace_back(r, f);
      batch.push(r, f);
    }
    const Vec3 ref = stokeslet_reference_sum(terms);
    double scale = 0;  // Σ |f|/|r|: the size of the terms, against which round-off is measured
    for (const auto& [r, f] : terms) scale += f.norm() / r.norm();
    // rsqrt with 2 Newton steps (or an exact division) and fused sums: a few ulp per term.
    EXPECT_LE((batch.sum() - ref).norm(), 1e-14 * std::max(scale, 1.0)) << "n = " << n << ", " << fmm::simd::isa_name();
  }
}

TEST(StokesletBatch, CoincidentPointContributesNothing) {
  StokesletBatch batch;
  batch.push(Vec3::Zero(), Vec3(1, 2, 3));  // r = 0: skipped by convention
  batch.push(Vec3(2, 0, 0), Vec3(1, 0, 0));
  const Vec3 u = batch.sum();
  // G(2 e1) e1 = e1/2 + e1/2 = e1 exactly.
  EXPECT_NEAR(u.x(), 1.0, 1e-15);
  EXPECT_EQ(u.y(), 0.0);
  EXPECT_EQ(u.z(), 0.0);
}

#ifdef CAPSFLOW_EXPECTED_ISA
TEST(StokesletBatch, CompiledForTheRequestedInstructionSet) {
  EXPECT_STREQ(fmm::simd::isa_name(), CAPSFLOW_EXPECTED_ISA);  // the variant build really is that variant
}
#endif
