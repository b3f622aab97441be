// The lab-frame centroid (geometry/lab_centroid.hpp) against closed forms of e^{Lτ} and φ1(Lτ):
// a diagonal strain (per component e^{λτ} and (e^{λτ} − 1)/(λτ)), and simple shear, where L is
// nilpotent (e^{Lτ} = I + Lτ, φ1(Lτ) = I + Lτ/2); and composition: two half steps of a centroid
// at rest in the frame give one whole step.
#include "capsflow/core/geometry/lab_centroid.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace capsflow;

TEST(LabCentroid, DiagonalStrainFollowsTheExponentialAndPhiOne) {
  Mat3 L = Mat3::Zero();
  L.diagonal() << 1, 0, -1;  // planar hyperbolic flow
  const Vec3 C(0.3, -0.2, 0.5), dc(1e-3, 2e-3, -4e-3);
  for (const double tau : {1e-3, 0.1, 1.0, 5.0}) {
    const Vec3 got = advance_lab_centroid(L, tau, C, dc);
    const double ep = std::exp(tau), em = std::exp(-tau);
    const Vec3 want(ep * C[0] + (ep - 1) / tau * dc[0], C[1] + dc[1], em * C[2] + (1 - em) / tau * dc[2]);
    for (int k = 0; k < 3; ++k)  // Padé scaling and squaring: a few ulps of e^5 = 148
      EXPECT_NEAR(got[k], want[k], 1e-13 * std::max(1.0, std::abs(want[k]))) << "tau " << tau << " k " << k;
  }
}

TEST(LabCentroid, SimpleShearIsNilpotent) {
  Mat3 L = Mat3::Zero();
  L(0, 1) = 1;  // v = x2 e1
  const Vec3 C(0.1, 0.4, -0.3), dc(0.01, -0.02, 0.03);
  const double tau = 2.5;
  const Vec3 want = (Mat3::Identity() + L * tau) * C + (Mat3::Identity() + L * tau / 2) * dc;
  EXPECT_LT((advance_lab_centroid(L, tau, C, dc) - want).norm(), 1e-14);
}

TEST(LabCentroid, HalfStepsComposeForACentroidAtRestInTheFrame) {
  Mat3 L;
  L << 0.2, 1.0, 0.0, -0.3, 0.1, 0.4, 0.0, 0.5, -0.3;  // trace-free, general
  const Vec3 C(1, 2, 3);
  const Vec3 whole = advance_lab_centroid(L, 0.8, C, Vec3::Zero());
  const Vec3 halves = advance_lab_centroid(L, 0.4, advance_lab_centroid(L, 0.4, C, Vec3::Zero()), Vec3::Zero());
  EXPECT_LT((whole - halves).norm(), 1e-13 * whole.norm());
  // At rest in the frame the centroid is a material point of the imposed flow: dC/dt = L C.
  const double h = 1e-6;
  const Vec3 rate = (advance_lab_centroid(L, h, C, Vec3::Zero()) - C) / h;
  EXPECT_LT((rate - L * C).norm(), 1e-5 * (L * C).norm());  // forward difference: O(h) = 1e-6 relative
}
