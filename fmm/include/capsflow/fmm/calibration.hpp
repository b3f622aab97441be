#pragma once
// capsflow::fmm calibration — tolerance -> order, default leaf size, and the measured crossover
// at which the FMM beats direct summation. Measured with perf/fmm/fmm_bench on the development
// machine (2 threads, AVX-512; see perf/fmm/RESULTS.md for the commands and raw numbers).
#include <cstddef>

namespace capsflow::fmm {

struct CalibrationRow {
  double tolerance;        ///< the row applies to requested tolerances >= this value
  int order;               ///< order p whose worst measured rel. L2 error is below `tolerance`
  int leaf_size;           ///< tuned points per leaf for that order
  std::size_t crossover;   ///< N (sources = targets, sphere surface) above which FMM < direct
};

// Ordered from loose to tight. `order` is the lowest p whose WORST relative L2 error over the
// sphere, spheroid (a/b = 1.4), uniform-cube and clustered distributions (N = 1e4, sources =
// targets and 3000 separate targets, 64 points per leaf) was below the tolerance:
//   p:      4        5        6        7        8        9        10       11
//   worst:  1.14e-3  1.99e-3  4.4e-5   2.3e-6   7.6e-7   7.0e-8   2.0e-8   2.6e-8
// (odd p = 5 is worse than p = 4; p >= 10 hits the double-precision floor of the 1e-10
// regularised pseudo-inverses, ~2e-8: see accuracy_floor()).
// leaf_size: best of {300..800} at N = 1e5 and 1e6 on the sphere. crossover: N at which setup +
// one evaluation beats direct_sum (sphere, sources = targets, 2 threads, perf/fmm/RESULTS.md:
// measured 4.2e3–5.3e3 at 1e-3 (p = 6), 6.8e3–1.0e4 at 1e-6 (p = 8), 1.1e4–1.3e4 at p = 10),
// rounded up; sources != targets use the geometric mean sqrt(n_src·n_trg).
inline constexpr CalibrationRow kCalibration[] = {
    {2e-3, 4, 200, 4000},
    {1e-4, 6, 300, 5000},
    {1e-5, 7, 400, 7000},
    {1e-6, 8, 500, 9000},
    {1e-7, 9, 600, 11000},
    {0.0, 10, 600, 12000},
};

/// Smallest relative L2 error the Stokeslet FMM reaches reliably in double precision (measured);
/// tighter requests get order 10 and this accuracy.
inline constexpr double accuracy_floor() { return 3e-8; }

inline const CalibrationRow& calibration_for(double tolerance) {
  constexpr int n = sizeof(kCalibration) / sizeof(kCalibration[0]);
  for (int i = 0; i < n; ++i)
    if (tolerance >= kCalibration[i].tolerance) return kCalibration[i];
  return kCalibration[n - 1];
}

/// Order p to reach a relative L2 error <= tolerance.
inline int order_for_tolerance(double tolerance) { return calibration_for(tolerance).order; }

/// Default points per leaf for an order.
inline int default_leaf_size(int order) {
  for (const auto& r : kCalibration)
    if (r.order >= order) return r.leaf_size;
  return kCalibration[sizeof(kCalibration) / sizeof(kCalibration[0]) - 1].leaf_size;
}

/// Measured crossover: for n_src·n_trg below crossover², direct_sum is faster than setup +
/// one evaluation of the FMM at this tolerance. Use for backend = "auto".
inline std::size_t direct_crossover(double tolerance) { return calibration_for(tolerance).crossover; }

inline bool prefer_direct(std::size_t n_src, std::size_t n_trg, double tolerance) {
  const double c = static_cast<double>(direct_crossover(tolerance));
  return static_cast<double>(n_src) * static_cast<double>(n_trg) < c * c;
}

}  // namespace capsflow::fmm
