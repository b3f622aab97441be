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

// Ordered from loose to tight. Worst rel. L2 error over the sphere, spheroid, cube and clustered
// distributions (N = 2e4, sources = targets and sources != targets) measured below the tolerance.
inline constexpr CalibrationRow kCalibration[] = {
    {1e-3, 4, 128, 8000},
    {1e-4, 5, 192, 10000},
    {1e-5, 6, 256, 12000},
    {1e-6, 8, 384, 16000},
    {1e-7, 9, 448, 20000},
    {1e-8, 10, 512, 25000},
    {1e-9, 12, 640, 40000},
    {1e-10, 14, 768, 60000},
};

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
