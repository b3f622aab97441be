// Kernel conventions (Stokeslet, Laplace), the SIMD pair kernel against the scalar reference, and
// the public direct_sum (overwrite semantics, sources != targets, empty inputs).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/direct_sum_mixed.hpp"
#include "capsflow/fmm/laplace.hpp"
#include "capsflow/fmm/stokeslet.hpp"

using namespace capsflow::fmm;
namespace {
constexpr double kPi = 3.14159265358979323846;

std::vector<double> random_points(std::size_t n, unsigned seed, double lo = -1, double hi = 1) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> p(3 * n);
  for (auto& v : p) v = u(g);
  return p;
}

double rel_l2(const std::vector<double>& a, const std::vector<double>& b) {
  double num = 0, den = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    num += (a[i] - b[i]) * (a[i] - b[i]);
    den += b[i] * b[i];
  }
  return std::sqrt(num / den);
}
}  // namespace

TEST(StokesletConvention, AxialAndTransverseValues) {
  // One unit force f = e1 at the origin. G(r) = I/|r| + r r^T/|r|^3, u = G f / (8π).
  const double src[3] = {0, 0, 0}, f[3] = {1, 0, 0};
  const double trg[6] = {2, 0, 0, 0, 2, 0};
  double u[6];
  direct_sum<Stokeslet>(src, 1, f, trg, 2, u);
  // axial: G_11 = 1/2 + 4/8 = 1 ; transverse: G_11 = 1/2. Exact closed forms, 1e-15 = rounding.
  EXPECT_NEAR(u[0], 1.0 / (8 * kPi), 1e-15);
  EXPECT_NEAR(u[1], 0.0, 1e-15);
  EXPECT_NEAR(u[3], 0.5 / (8 * kPi), 1e-15);
  EXPECT_NEAR(u[4], 0.0, 1e-15);
}

TEST(StokesletConvention, OffDiagonalAndHomogeneity) {
  // r = x − y = (1,2,2) − (0,0,0), |r| = 3; G f with f = e2: (r1 r2/27, 1/3 + 4/27, r3 r2/27).
  const double src[3] = {0, 0, 0}, f[3] = {0, 1, 0}, trg[3] = {1, 2, 2};
  double u[3];
  direct_sum<Stokeslet>(src, 1, f, trg, 1, u);
  const double s = 1.0 / (8 * kPi);
  EXPECT_NEAR(u[0], s * 2.0 / 27, 1e-15);  // exact rational value; 1e-15 = rounding
  EXPECT_NEAR(u[1], s * (1.0 / 3 + 4.0 / 27), 1e-15);
  EXPECT_NEAR(u[2], s * 4.0 / 27, 1e-15);
  // degree −1: scale positions by 10 -> u/10 (same rounding bound, 1e-16 absolute)
  const double trg10[3] = {10, 20, 20};
  double u10[3];
  direct_sum<Stokeslet>(src, 1, f, trg10, 1, u10);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(u10[k], u[k] / 10, 1e-16);
  EXPECT_EQ(Stokeslet::homogeneity, -1);
  EXPECT_DOUBLE_EQ(Stokeslet::scale(), 1.0 / (8 * kPi));
}

TEST(StokesletConvention, SelfPairSkippedAndOutputOverwritten) {
  // two sources; a target on the first only feels the second
  const double src[6] = {0, 0, 0, 0, 0, 3}, f[6] = {5, 5, 5, 0, 0, 1};
  const double trg[3] = {0, 0, 0};
  double u[3] = {123, 456, 789};  // garbage must be overwritten
  direct_sum<Stokeslet>(src, 2, f, trg, 1, u);
  // r = (0,0,−3), f = e3: G f = e3 (1/3 + 9/27) = (2/3) e3
  EXPECT_NEAR(u[0], 0.0, 1e-15);
  EXPECT_NEAR(u[1], 0.0, 1e-15);
  EXPECT_NEAR(u[2], (2.0 / 3) / (8 * kPi), 1e-15);
}

TEST(LaplaceConvention, OneOverFourPiR) {
  const double src[6] = {0, 0, 0, 1, 1, 1}, q[2] = {2.0, 7.0}, trg[3] = {0, 0, 4};
  double u[1] = {99};
  direct_sum<Laplace>(src, 2, q, trg, 1, u);
  const double expect = (2.0 / 4 + 7.0 / std::sqrt(1 + 1 + 9)) / (4 * kPi);
  EXPECT_NEAR(u[0], expect, 1e-15);  // closed form; 1e-15 = rounding
}

TEST(DirectSum, EmptyInputsGiveZeros) {
  std::vector<double> trg = random_points(5, 1), u(15, 42.0);
  direct_sum<Stokeslet>(nullptr, 0, nullptr, trg.data(), 5, u.data());
  for (double v : u) EXPECT_EQ(v, 0.0);  // no sources: exactly zero
  direct_sum<Stokeslet>(trg.data(), 5, trg.data(), nullptr, 0, nullptr);  // no targets: no-op
}

template <class Kernel>
void check_simd_against_scalar(std::size_t ns, std::size_t nt) {
  constexpr int SD = Kernel::src_dim, TD = Kernel::trg_dim;
  auto s = random_points(ns, 7), t = random_points(nt, 8);
  if (nt > 5 && ns > 11)
    for (int d = 0; d < 3; ++d) t[3 * 5 + d] = s[3 * 11 + d];  // a coincident pair (skipped)
  std::vector<double> f(ns * SD);
  std::mt19937_64 g(9);
  std::normal_distribution<double> nd;
  for (auto& v : f) v = nd(g);
  // SoA views
  std::vector<double> sx(ns), sy(ns), sz(ns), tx(nt), ty(nt), tz(nt);
  std::vector<std::vector<double>> fs(SD, std::vector<double>(ns));
  for (std::size_t j = 0; j < ns; ++j) {
    sx[j] = s[3 * j]; sy[j] = s[3 * j + 1]; sz[j] = s[3 * j + 2];
    for (int k = 0; k < SD; ++k) fs[k][j] = f[SD * j + k];
  }
  for (std::size_t i = 0; i < nt; ++i) { tx[i] = t[3 * i]; ty[i] = t[3 * i + 1]; tz[i] = t[3 * i + 2]; }
  const double* fp[SD];
  for (int k = 0; k < SD; ++k) fp[k] = fs[k].data();
  std::vector<std::vector<double>> ua(TD, std::vector<double>(nt, 0.0)), ub = ua;
  double* pa[TD];
  double* pb[TD];
  for (int k = 0; k < TD; ++k) { pa[k] = ua[k].data(); pb[k] = ub[k].data(); }
  p2p<Kernel>(tx.data(), ty.data(), tz.data(), nt, sx.data(), sy.data(), sz.data(), fp, ns, pa, 1.0);
  p2p_reference<Kernel>(tx.data(), ty.data(), tz.data(), nt, sx.data(), sy.data(), sz.data(), fp, ns,
                        pb, 1.0);
  std::vector<double> a, b;
  for (int k = 0; k < TD; ++k) { a.insert(a.end(), ua[k].begin(), ua[k].end()); b.insert(b.end(), ub[k].begin(), ub[k].end()); }
  // 1e-13: rsqrt + two Newton steps is accurate to ~1e-16 per pair; ~1000-term sums in a
  // different FMA grouping add ~1e-15; anything larger is a wrong lane, mask or remainder.
  EXPECT_LT(rel_l2(a, b), 1e-13) << simd::isa_name();
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(std::isfinite(a[i]));  // self pair masked
}

TEST(P2PSimd, StokesletMatchesScalarReference) {
  check_simd_against_scalar<Stokeslet>(1000, 333);  // 333: not a multiple of any vector width
  check_simd_against_scalar<Stokeslet>(7, 3);
}
TEST(P2PSimd, LaplaceMatchesScalarReference) { check_simd_against_scalar<Laplace>(1000, 333); }

TEST(DirectSum, SourcesDifferFromTargetsMatchesReference) {
  // 5000 sources (spans two source tiles), 700 targets in caller order, AoS in/out.
  const std::size_t ns = 5000, nt = 700;
  auto s = random_points(ns, 3), t = random_points(nt, 4, -2, 2);
  std::vector<double> f(3 * ns);
  std::mt19937_64 g(5);
  std::normal_distribution<double> nd;
  for (auto& v : f) v = nd(g);
  std::vector<double> u(3 * nt);
  direct_sum<Stokeslet>(s.data(), ns, f.data(), t.data(), nt, u.data(), 2);
  std::vector<double> ref(3 * nt, 0.0);
  for (std::size_t i = 0; i < nt; ++i)
    for (std::size_t j = 0; j < ns; ++j) {
      double r[3], r2 = 0;
      for (int d = 0; d < 3; ++d) { r[d] = t[3 * i + d] - s[3 * j + d]; r2 += r[d] * r[d]; }
      const double ri = 1 / std::sqrt(r2), fr = (r[0] * f[3 * j] + r[1] * f[3 * j + 1] + r[2] * f[3 * j + 2]);
      for (int d = 0; d < 3; ++d) ref[3 * i + d] += (f[3 * j + d] * ri + r[d] * fr * ri * ri * ri) / (8 * kPi);
    }
  EXPECT_LT(rel_l2(u, ref), 1e-13);  // same bound and reason as the SIMD test
}

// The mixed-precision Stokeslet direct sum (single-precision pairs, double sums) against the
// double one, on a surface-like cloud and the same cloud moved 100 units away (the per-block
// shift must keep nearby pairs accurate far from the origin).
TEST(DirectSumMixed, MatchesDoublePrecisionWithinItsStatedAccuracy) {
  std::mt19937_64 g(11);
  std::normal_distribution<double> N;
  const std::size_t ns = 6000, nt = 1500;
  std::vector<double> s(3 * ns), t(3 * nt), f(3 * ns);
  auto on_sphere = [&](double* p) {
    double x = N(g), y = N(g), z = N(g);
    const double r = std::sqrt(x * x + y * y + z * z);
    p[0] = x / r, p[1] = y / r, p[2] = z / r;
  };
  for (std::size_t j = 0; j < ns; ++j) on_sphere(&s[3 * j]);
  for (std::size_t i = 0; i < nt; ++i) on_sphere(&t[3 * i]);
  for (auto& v : f) v = N(g);
  for (const double shift : {0.0, 100.0}) {
    std::vector<double> ss = s, tt = t, ref(3 * nt), mixed(3 * nt, 7.0);
    for (std::size_t j = 0; j < ns; ++j) ss[3 * j] += shift;
    for (std::size_t i = 0; i < nt; ++i) tt[3 * i] += shift;
    direct_sum<Stokeslet>(ss.data(), ns, f.data(), tt.data(), nt, ref.data());
    stokeslet_direct_sum_mixed(ss.data(), ns, f.data(), tt.data(), nt, mixed.data());
    double emax = 0, umax = 0, e2 = 0, u2 = 0;
    for (std::size_t k = 0; k < 3 * nt; ++k) {
      emax = std::max(emax, std::abs(mixed[k] - ref[k]));
      umax = std::max(umax, std::abs(ref[k]));
      e2 += (mixed[k] - ref[k]) * (mixed[k] - ref[k]);
      u2 += ref[k] * ref[k];
    }
    // Float pairs carry ~6e-8 relative error each (rounding of r, rsqrt + 1 Newton step); with
    // random signs over 6000 sources the sum keeps ~1e-7 relative in L2. The max-norm bound
    // 2e-6 is the 1e-5 tolerance from which the boundary integral uses this sum, with a 5x margin.
    EXPECT_LT(std::sqrt(e2 / u2), 5e-7) << "shift " << shift;
    EXPECT_LT(emax / umax, 2e-6) << "shift " << shift;
  }
}
