#pragma once
// capsflow::fmm::simd — a minimal double-precision vector type for the pair kernels.
//
// VecD wraps the widest vector the compiler was told about: AVX-512 (8 lanes), AVX2+FMA (4 lanes),
// or a plain double (1 lane, the portable fallback; loops around it carry `#pragma omp simd`).
// Kernels are written once against this type (and against plain double for the scalar reference).
// rsqrt(r2) returns 1/sqrt(r2) to full double accuracy and 0 where r2 == 0 (self pairs skipped).
// VecF, with AVX-512 (16 lanes) or AVX2 (8), is the single-precision pair type of p2p_mixed.hpp.
#include <cmath>
#include <cstddef>

#if defined(__AVX512F__) || defined(__AVX2__)
#include <immintrin.h>
#endif

namespace capsflow::fmm::simd {

#if defined(__AVX512F__)
struct VecD {
  __m512d v;
  static constexpr int width = 8;
  VecD() = default;
  VecD(__m512d x) : v(x) {}
  explicit VecD(double x) : v(_mm512_set1_pd(x)) {}
  static VecD load(const double* p) { return _mm512_loadu_pd(p); }
  // lanes >= n are zero
  static VecD load_partial(const double* p, int n) {
    return _mm512_maskz_loadu_pd(static_cast<__mmask8>((1u << n) - 1u), p);
  }
  void store(double* p) const { _mm512_storeu_pd(p, v); }
  void add_to(double* p) const { _mm512_storeu_pd(p, _mm512_add_pd(_mm512_loadu_pd(p), v)); }
  void add_to_partial(double* p, int n) const {
    const __mmask8 m = static_cast<__mmask8>((1u << n) - 1u);
    _mm512_mask_storeu_pd(p, m, _mm512_add_pd(_mm512_maskz_loadu_pd(m, p), v));
  }
};
inline VecD operator+(VecD a, VecD b) { return _mm512_add_pd(a.v, b.v); }
inline VecD operator-(VecD a, VecD b) { return _mm512_sub_pd(a.v, b.v); }
inline VecD operator*(VecD a, VecD b) { return _mm512_mul_pd(a.v, b.v); }
inline VecD fma(VecD a, VecD b, VecD c) { return _mm512_fmadd_pd(a.v, b.v, c.v); }
inline VecD fnma(VecD a, VecD b, VecD c) { return _mm512_fnmadd_pd(a.v, b.v, c.v); }
// 14-bit hardware estimate refined by Newton steps (14 -> 28 -> 56 bits); masked at r2 == 0.
// Newton = 2: full double accuracy. Newton = 1: relative error < 6e-9 (used by the FMM near field
// when the requested tolerance is >= 1e-6, where it is invisible). Masked = false skips the
// r2 == 0 test: only for point sets known to be disjoint (distinct octree boxes).
template <int Newton = 2, bool Masked = true>
inline VecD rsqrt(VecD r2) {
  const __m512d half = _mm512_set1_pd(0.5), three_half = _mm512_set1_pd(1.5);
  __m512d y = _mm512_maskz_rsqrt14_pd(static_cast<__mmask8>(0xFF), r2.v);
  const __m512d hr2 = _mm512_mul_pd(half, r2.v);
  for (int it = 0; it < Newton; ++it)
    y = _mm512_mul_pd(y, _mm512_fnmadd_pd(hr2, _mm512_mul_pd(y, y), three_half));
  if constexpr (!Masked) return y;
  const __mmask8 nz = _mm512_cmp_pd_mask(r2.v, _mm512_setzero_pd(), _CMP_GT_OQ);
  return _mm512_maskz_mov_pd(nz, y);
}

// 16 single-precision lanes: the pair type of the mixed-precision pairs (p2p_mixed.hpp), so that
// they use the same kernel formula as every other path.
struct VecF {
  __m512 v;
  static constexpr int width = 16;
  VecF() = default;
  VecF(__m512 x) : v(x) {}
  explicit VecF(float x) : v(_mm512_set1_ps(x)) {}
  static VecF load(const float* p) { return _mm512_loadu_ps(p); }
  void store(float* p) const { _mm512_storeu_ps(p, v); }
};
inline VecF operator+(VecF a, VecF b) { return _mm512_add_ps(a.v, b.v); }
inline VecF operator-(VecF a, VecF b) { return _mm512_sub_ps(a.v, b.v); }
inline VecF operator*(VecF a, VecF b) { return _mm512_mul_ps(a.v, b.v); }
inline VecF fma(VecF a, VecF b, VecF c) { return _mm512_fmadd_ps(a.v, b.v, c.v); }
// 14-bit hardware estimate and one Newton step (~2⁻²⁷ relative); no r2 == 0 mask.
inline VecF rsqrt(VecF r2) {
  const __m512 half = _mm512_set1_ps(0.5f), three_half = _mm512_set1_ps(1.5f);
  const __m512 y = _mm512_rsqrt14_ps(r2.v);
  return _mm512_mul_ps(y, _mm512_fnmadd_ps(_mm512_mul_ps(half, r2.v), _mm512_mul_ps(y, y), three_half));
}
// y where r2 > 0, else 0 (a self pair adds nothing)
inline VecF zero_where_coincident(VecF y, VecF r2) {
  return _mm512_maskz_mov_ps(_mm512_cmp_ps_mask(r2.v, _mm512_setzero_ps(), _CMP_GT_OQ), y.v);
}
#elif defined(__AVX2__) && defined(__FMA__)
struct VecD {
  __m256d v;
  static constexpr int width = 4;
  VecD() = default;
  VecD(__m256d x) : v(x) {}
  explicit VecD(double x) : v(_mm256_set1_pd(x)) {}
  static VecD load(const double* p) { return _mm256_loadu_pd(p); }
  static VecD load_partial(const double* p, int n) {
    alignas(32) double t[4] = {0, 0, 0, 0};
    for (int i = 0; i < n; ++i) t[i] = p[i];
    return _mm256_load_pd(t);
  }
  void store(double* p) const { _mm256_storeu_pd(p, v); }
  void add_to(double* p) const { _mm256_storeu_pd(p, _mm256_add_pd(_mm256_loadu_pd(p), v)); }
  void add_to_partial(double* p, int n) const {
    alignas(32) double t[4];
    _mm256_store_pd(t, v);
    for (int i = 0; i < n; ++i) p[i] += t[i];
  }
};
inline VecD operator+(VecD a, VecD b) { return _mm256_add_pd(a.v, b.v); }
inline VecD operator-(VecD a, VecD b) { return _mm256_sub_pd(a.v, b.v); }
inline VecD operator*(VecD a, VecD b) { return _mm256_mul_pd(a.v, b.v); }
inline VecD fma(VecD a, VecD b, VecD c) { return _mm256_fmadd_pd(a.v, b.v, c.v); }
inline VecD fnma(VecD a, VecD b, VecD c) { return _mm256_fnmadd_pd(a.v, b.v, c.v); }
// Exact 1/sqrt (no float conversion, so any double range is safe); masked at r2 == 0.
template <int Newton = 2, bool Masked = true>
inline VecD rsqrt(VecD r2) {
  const __m256d zero = _mm256_setzero_pd();
  const __m256d y = _mm256_div_pd(_mm256_set1_pd(1.0), _mm256_sqrt_pd(r2.v));
  return _mm256_and_pd(y, _mm256_cmp_pd(r2.v, zero, _CMP_GT_OQ));
}

// 8 single-precision lanes: the pair type of the mixed-precision pairs (p2p_mixed.hpp). Without
// AVX-512 the exact double 1/sqrt needs the divider, which bounds the double pairs' throughput;
// these pairs avoid it and carry twice the lanes (perf/fmm/RESULTS.md, "Single-precision pairs").
struct VecF {
  __m256 v;
  static constexpr int width = 8;
  VecF() = default;
  VecF(__m256 x) : v(x) {}
  explicit VecF(float x) : v(_mm256_set1_ps(x)) {}
  static VecF load(const float* p) { return _mm256_loadu_ps(p); }
  void store(float* p) const { _mm256_storeu_ps(p, v); }
};
inline VecF operator+(VecF a, VecF b) { return _mm256_add_ps(a.v, b.v); }
inline VecF operator-(VecF a, VecF b) { return _mm256_sub_ps(a.v, b.v); }
inline VecF operator*(VecF a, VecF b) { return _mm256_mul_ps(a.v, b.v); }
inline VecF fma(VecF a, VecF b, VecF c) { return _mm256_fmadd_ps(a.v, b.v, c.v); }
// 12-bit hardware estimate and one Newton step (~2e-7 relative); no r2 == 0 mask.
inline VecF rsqrt(VecF r2) {
  const __m256 half = _mm256_set1_ps(0.5f), three_half = _mm256_set1_ps(1.5f);
  const __m256 y = _mm256_rsqrt_ps(r2.v);
  return _mm256_mul_ps(y, _mm256_fnmadd_ps(_mm256_mul_ps(half, r2.v), _mm256_mul_ps(y, y), three_half));
}
inline VecF zero_where_coincident(VecF y, VecF r2) {
  return _mm256_and_ps(y.v, _mm256_cmp_ps(r2.v, _mm256_setzero_ps(), _CMP_GT_OQ));
}
#else
struct VecD {
  double v;
  static constexpr int width = 1;
  VecD() = default;
  explicit VecD(double x) : v(x) {}
  static VecD load(const double* p) { return VecD(*p); }
  static VecD load_partial(const double* p, int n) { return VecD(n > 0 ? *p : 0.0); }
  void store(double* p) const { *p = v; }
  void add_to(double* p) const { *p += v; }
  void add_to_partial(double* p, int n) const { if (n > 0) *p += v; }
};
inline VecD operator+(VecD a, VecD b) { return VecD(a.v + b.v); }
inline VecD operator-(VecD a, VecD b) { return VecD(a.v - b.v); }
inline VecD operator*(VecD a, VecD b) { return VecD(a.v * b.v); }
inline VecD fma(VecD a, VecD b, VecD c) { return VecD(a.v * b.v + c.v); }
inline VecD fnma(VecD a, VecD b, VecD c) { return VecD(c.v - a.v * b.v); }
template <int Newton = 2, bool Masked = true>
inline VecD rsqrt(VecD r2) { return VecD(r2.v > 0 ? 1.0 / std::sqrt(r2.v) : 0.0); }
#endif

// Scalar overloads so that kernels templated on the value type also work with plain double.
inline double fma(double a, double b, double c) { return a * b + c; }
inline double rsqrt(double r2) { return r2 > 0 ? 1.0 / std::sqrt(r2) : 0.0; }

/// True where VecF exists (AVX-512 or AVX2 + FMA): the single-precision pairs of p2p_mixed.hpp.
#if defined(__AVX512F__) || (defined(__AVX2__) && defined(__FMA__))
inline constexpr bool kHasSinglePrecisionPairs = true;
#else
inline constexpr bool kHasSinglePrecisionPairs = false;
#endif

/// Name of the active vector path, for reports.
inline const char* isa_name() {
#if defined(__AVX512F__)
  return "avx512";
#elif defined(__AVX2__) && defined(__FMA__)
  return "avx2";
#else
  return "scalar";
#endif
}

}  // namespace capsflow::fmm::simd
