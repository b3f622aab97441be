// The director field (director.hpp): minimal rotations, nodal triads under many rotations, and the
// area-weighted normals shared by the wall and core's geometry.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "capsflow/shell/director.hpp"
#include "support/wall_fixtures.hpp"

using namespace capsflow::shell;
using namespace capsflow::shell::testing;

namespace {
Vec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<double> N(0, 1);
  return Vec3(N(rng), N(rng), N(rng)).normalized();
}
}  // namespace

TEST(Director, MinimalRotationTakesOneUnitVectorToTheOther) {
  std::mt19937 rng(3);
  for (int k = 0; k < 200; ++k) {
    const Vec3 a = random_unit(rng), b = random_unit(rng);
    Vec3 w;
    ASSERT_TRUE(minimal_rotation(a, b, w));
    // Rodrigues is exact for any angle: the image of a is b to a few ulps of O(1) terms
    EXPECT_LT((rodrigues(w, a) - b).norm(), 1e-14);
    EXPECT_NEAR(w.norm(), std::acos(std::clamp(a.dot(b), -1.0, 1.0)), 1e-7);  // acos loses ~√ε near 0, π
    EXPECT_LT(std::abs(w.dot(a)), 1e-14);  // the axis is normal to both: the smallest rotation
  }
  Vec3 w(1, 2, 3);
  const Vec3 a(0, 0, 1);
  EXPECT_FALSE(minimal_rotation(a, a, w));  // parallel: nothing to rotate
}

TEST(Director, NodalTriadsStayOrthonormalAndRightHandedUnderManyRotations) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  Points d(50, 3);
  for (int i = 0; i < 50; ++i) d.row(i) = 3.0 * random_unit(rng).transpose();  // not unit: normalised
  NodalTriads T(d);
  for (int i = 0; i < 50; ++i) EXPECT_LT((Vec3(T.d.row(i)) - Vec3(d.row(i)) / 3.0).norm(), 1e-15);
  // 2000 increments of up to ~1.7 rad each, as a long run of Newton steps and predictor turns
  for (int step = 0; step < 2000; ++step)
    for (int i = 0; i < 50; ++i) T.rotate(i, Vec3(U(rng), U(rng), U(rng)));
  for (int i = 0; i < 50; ++i) {
    const Vec3 a = T.t1.row(i), b = T.t2.row(i), n = T.d.row(i);
    // re-orthonormalised at every rotation: errors do not accumulate beyond a few ulps
    EXPECT_NEAR(a.norm(), 1.0, 1e-14);
    EXPECT_NEAR(b.norm(), 1.0, 1e-14);
    EXPECT_NEAR(n.norm(), 1.0, 1e-14);
    EXPECT_LT(std::abs(a.dot(n)), 1e-14);
    EXPECT_LT((a.cross(b) - n).norm(), 1e-14);  // right-handed: t1 × t2 = d
  }
}

TEST(Director, RotatingATriadMovesItsDirectorByRodrigues) {
  std::mt19937 rng(7);
  Points d(1, 3);
  d.row(0) = random_unit(rng).transpose();
  NodalTriads T(d);
  const Vec3 w = 2.5 * random_unit(rng), d0 = T.d.row(0), t0 = T.t1.row(0);
  T.rotate(0, w);
  EXPECT_LT((Vec3(T.d.row(0)) - rodrigues(w, d0)).norm(), 1e-15);
  EXPECT_LT((Vec3(T.t1.row(0)) - rodrigues(w, t0)).norm(), 1e-14);  // t1 carried by the same rotation
}

TEST(Director, AreaWeightedNormalsAreOneFormulaForAnyThreadCount) {
  Mesh m = icosphere(5);  // 10 242 nodes: above the node-loop threshold, so the loop runs on a team
  const Points x = deform(m.X, 1.0, 3);
  const Topology topo(m.T, x.rows());
  const int nt = omp_get_max_threads();
  Points n1, n2;
  omp_set_num_threads(1);
  area_weighted_normals(x, topo, n1);
  omp_set_num_threads(std::max(2, nt));
  area_weighted_normals(x, topo, n2);
  omp_set_num_threads(nt);
  EXPECT_EQ((n1 - n2).cwiseAbs().maxCoeff(), 0.0);                             // bit-equality
  EXPECT_EQ((area_weighted_normals(x, m.T) - n1).cwiseAbs().maxCoeff(), 0.0);  // both entry points
  // Independent check of the formula: the normalised sum of the facet area vectors, by a scatter
  // over the elements (a different loop, so equal to rounding only).
  Points s = Points::Zero(x.rows(), 3);
  for (Eigen::Index e = 0; e < m.T.rows(); ++e) {
    const Vec3 a = x.row(m.T(e, 0)), b = x.row(m.T(e, 1)), c = x.row(m.T(e, 2));
    for (int k = 0; k < 3; ++k) s.row(m.T(e, k)) += (b - a).cross(c - a).transpose();
  }
  for (Eigen::Index i = 0; i < s.rows(); ++i) s.row(i).normalize();
  EXPECT_LT((s - n1).cwiseAbs().maxCoeff(), 1e-15);  // unit vectors summed in the same order: ulps
}
