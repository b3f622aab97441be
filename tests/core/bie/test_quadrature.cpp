// The quadrature rules of bie/quadrature.hpp against exact integrals: Gauss–Legendre on [0, 1] is
// exact to degree 2n − 1 and misses degree 2n by its remainder formula; the triangle rules
// integrate barycentric monomials exactly to their stated degree, ∫_T λ0^a λ1^b λ2^c dA / A = 2 a! b! c! / (a + b + c + 2)!.
#include "capsflow/core/bie/quadrature.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace capsflow;

namespace {
double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }
double exact_monomial(int a, int b, int c) { return 2 * factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 2); }

template <int N>
double triangle_rule(const double (&bary)[N][3], const double* weights, int a, int b, int c) {
  double s = 0;
  for (int g = 0; g < N; ++g) s += weights[g] * std::pow(bary[g][0], a) * std::pow(bary[g][1], b) * std::pow(bary[g][2], c);
  return s;
}
}  // namespace

TEST(Quadrature, GaussLegendreIsExactToDegreeTwoNMinusOne) {
  for (int n : {1, 2, 3, 5, 8}) {
    const GaussLegendre r(n);
    ASSERT_EQ(static_cast<int>(r.x.size()), n);
    for (int d = 0; d <= 2 * n; ++d) {
      double s = 0;
      for (int i = 0; i < n; ++i) s += r.w[i] * std::pow(r.x[i], d);
      if (d <= 2 * n - 1) EXPECT_NEAR(s, 1.0 / (d + 1), 1e-14) << "n " << n << " degree " << d;  // round-off
      // and no more: degree 2n is underestimated by exactly the remainder (n!)⁴ / ((2n + 1) ((2n)!)²) on
      // [0, 1] (its error term with f^(2n) = (2n)!); relative 1e-6: round-off of a 3.6e-10 difference
      else EXPECT_NEAR(1.0 / (d + 1) - s, std::pow(factorial(n), 4) / ((2 * n + 1) * std::pow(factorial(2 * n), 2)),
                       1e-6 * std::pow(factorial(n), 4) / ((2 * n + 1) * std::pow(factorial(2 * n), 2)) + 1e-15)
          << "n " << n << " degree " << d;
    }
  }
}

TEST(Quadrature, TriangleRulesIntegrateToTheirDegree) {
  const double third[3] = {1.0 / 3, 1.0 / 3, 1.0 / 3};
  double dunavant_bary[7][3], dunavant_w[7];
  for (int g = 0; g < 7; ++g) {
    for (int k = 0; k < 3; ++k) dunavant_bary[g][k] = kDunavant7[g][k];
    dunavant_w[g] = kDunavant7[g][3];
  }
  for (int a = 0; a <= 5; ++a)
    for (int b = 0; a + b <= 5; ++b)
      for (int c = 0; a + b + c <= 5; ++c) {
        const int degree = a + b + c;
        const double exact = exact_monomial(a, b, c);
        EXPECT_NEAR(triangle_rule(dunavant_bary, dunavant_w, a, b, c), exact, 1e-14) << a << b << c;  // degree 5
        if (degree <= 2) {
          EXPECT_NEAR(triangle_rule(kGaussBary, third, a, b, c), exact, 1e-15) << a << b << c;
          EXPECT_NEAR(triangle_rule(kEdgeMidpointBary, third, a, b, c), exact, 1e-15) << a << b << c;
        }
      }
  // Degree 3 is beyond the 3-point rules: λ0³ is missed by both (their cubic errors differ 9×).
  const double exact = exact_monomial(3, 0, 0);
  const double e_gauss = triangle_rule(kGaussBary, third, 3, 0, 0) - exact;
  const double e_mid = triangle_rule(kEdgeMidpointBary, third, 3, 0, 0) - exact;
  EXPECT_GT(std::abs(e_gauss), 1e-4);
  EXPECT_NEAR(e_mid / e_gauss, -9.0, 1e-9);
}
