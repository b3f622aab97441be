#pragma once
// Second-order forward automatic differentiation: a scalar carrying its value, gradient and
// (packed upper-triangular) Hessian with respect to N independent variables. Used to obtain exact
// element stiffness matrices from the templated element energy (element_energy_t) for the forward
// static mode and as a test oracle for the hand-coded tangents. Supports + - * / and sqrt.
#include <array>
#include <cmath>

namespace capsflow::shell {

template <int N>
struct Hyper {
  static constexpr int NH = N * (N + 1) / 2;
  double v = 0;
  std::array<double, N> g{};
  std::array<double, NH> h{};

  Hyper() = default;
  Hyper(double x) : v(x) {}  // NOLINT: implicit from constants
  static Hyper variable(double x, int i) {
    Hyper r(x);
    r.g[i] = 1.0;
    return r;
  }
  static constexpr int idx(int i, int j) {  // i <= j
    return i * N - i * (i - 1) / 2 + (j - i);
  }
  double hess(int i, int j) const { return i <= j ? h[idx(i, j)] : h[idx(j, i)]; }
};

// f(a) with f', f'' (chain rule)
template <int N>
Hyper<N> chain(const Hyper<N>& a, double f, double f1, double f2) {
  Hyper<N> r(f);
  for (int i = 0; i < N; ++i) r.g[i] = f1 * a.g[i];
  int k = 0;
  for (int i = 0; i < N; ++i)
    for (int j = i; j < N; ++j, ++k) r.h[k] = f1 * a.h[k] + f2 * a.g[i] * a.g[j];
  return r;
}

template <int N> Hyper<N> operator+(const Hyper<N>& a, const Hyper<N>& b) {
  Hyper<N> r(a.v + b.v);
  for (int i = 0; i < N; ++i) r.g[i] = a.g[i] + b.g[i];
  for (int k = 0; k < Hyper<N>::NH; ++k) r.h[k] = a.h[k] + b.h[k];
  return r;
}
template <int N> Hyper<N> operator-(const Hyper<N>& a, const Hyper<N>& b) {
  Hyper<N> r(a.v - b.v);
  for (int i = 0; i < N; ++i) r.g[i] = a.g[i] - b.g[i];
  for (int k = 0; k < Hyper<N>::NH; ++k) r.h[k] = a.h[k] - b.h[k];
  return r;
}
template <int N> Hyper<N> operator-(const Hyper<N>& a) { return chain(a, -a.v, -1.0, 0.0); }
template <int N> Hyper<N> operator*(const Hyper<N>& a, const Hyper<N>& b) {
  Hyper<N> r(a.v * b.v);
  for (int i = 0; i < N; ++i) r.g[i] = a.g[i] * b.v + a.v * b.g[i];
  int k = 0;
  for (int i = 0; i < N; ++i)
    for (int j = i; j < N; ++j, ++k)
      r.h[k] = a.h[k] * b.v + a.v * b.h[k] + a.g[i] * b.g[j] + a.g[j] * b.g[i];
  return r;
}
template <int N> Hyper<N> operator*(double s, const Hyper<N>& a) { return chain(a, s * a.v, s, 0.0); }
template <int N> Hyper<N> operator*(const Hyper<N>& a, double s) { return s * a; }
template <int N> Hyper<N> operator+(const Hyper<N>& a, double s) { Hyper<N> r = a; r.v += s; return r; }
template <int N> Hyper<N> operator+(double s, const Hyper<N>& a) { return a + s; }
template <int N> Hyper<N> operator-(const Hyper<N>& a, double s) { Hyper<N> r = a; r.v -= s; return r; }
template <int N> Hyper<N> operator-(double s, const Hyper<N>& a) { return chain(a, s - a.v, -1.0, 0.0); }
template <int N> Hyper<N> reciprocal(const Hyper<N>& a) {
  const double iv = 1.0 / a.v;
  return chain(a, iv, -iv * iv, 2.0 * iv * iv * iv);
}
template <int N> Hyper<N> operator/(const Hyper<N>& a, const Hyper<N>& b) { return a * reciprocal(b); }
template <int N> Hyper<N> operator/(double s, const Hyper<N>& b) { return s * reciprocal(b); }
template <int N> Hyper<N> operator/(const Hyper<N>& a, double s) { return (1.0 / s) * a; }
template <int N> Hyper<N> sqrt(const Hyper<N>& a) {
  const double s = std::sqrt(a.v);
  return chain(a, s, 0.5 / s, -0.25 / (s * a.v));
}

}  // namespace capsflow::shell
