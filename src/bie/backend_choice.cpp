#include "capsflow/core/bie/backend_choice.hpp"

#include <fmt/core.h>

#include "capsflow/fmm/calibration.hpp"
#include "capsflow/fmm/direct_sum_mixed.hpp"

namespace capsflow {

namespace {
// Single-precision pairs (max relative error ~5e-7, fmm/direct_sum_mixed.hpp) leave a 20x margin
// from this tolerance on.
constexpr double kMixedPrecisionTolerance = 1e-5;
// The double layer's FMM/direct crossover: the stresslet calibration's at kFmmToleranceMargin ×
// tolerance (its rule relative to the image: 28 900 at 1e-6), not at the lower order the double
// layer runs (15 000 at p = 9), which would switch too early at the boundary integral's sizes:
// measured at 20 480 elements (sqrt(sources × targets) = 17 700), Fig. 4 at λ = 5 to γ̇t = 0.2,
// 2 threads, the second-kind solve 0.48 s per evaluation direct against 0.55 by the FMM at p = 9;
// at 81 920 (70 950) the FMM's application is 3× faster (perf/RESULTS.md §2.2).
std::size_t stresslet_crossover(double tolerance) {
  return fmm::direct_crossover<fmm::Stresslet>(kFmmToleranceMargin * tolerance);
}
bool below_crossover(double n_src, double n_trg, double crossover) { return n_src * n_trg < crossover * crossover; }
}  // namespace

double double_layer_fmm_tolerance(double l2_allowed, double max_allowed) {
  for (const DoubleLayerOrderRow& row : kDoubleLayerOrders)
    if (2 * row.l2 <= l2_allowed && row.max <= max_allowed) {
      const double t = fmm::tolerance_for_order<fmm::Stresslet>(row.order);
      if (t > 0) return t;
    }
  return l2_allowed;
}

const SingleLayerCrossoverRow& single_layer_crossover(double tolerance) {
  constexpr int n = sizeof(kSingleLayerCrossover) / sizeof(kSingleLayerCrossover[0]);
  for (int i = 0; i < n - 1; ++i)
    if (tolerance >= kSingleLayerCrossover[i].tolerance) return kSingleLayerCrossover[i];
  return kSingleLayerCrossover[n - 1];
}

bool uses_mixed_precision(double tolerance) {
  // Single-precision pairs (max relative error ~5e-7, fmm/p2p_mixed.hpp) whenever the tolerance
  // leaves a 20x margin: every pair of the direct sum, the FMM's direct near field; tighter
  // tolerances stay in double.
  return fmm::kMixedPrecisionDirectSum && tolerance >= kMixedPrecisionTolerance;
}

FarFieldBackend choose_backend(BackendRequest requested, FarFieldKernel kernel, Eigen::Index n_sources, Eigen::Index n_targets,
                               double tolerance, std::string* reason) {
  const std::size_t n_src = static_cast<std::size_t>(n_sources), n_trg = static_cast<std::size_t>(n_targets);
  std::string why;
  FarFieldBackend b;
  if (requested == BackendRequest::Auto) {
    std::size_t c;
    std::string whose;
    if (kernel == FarFieldKernel::SingleLayer) {
      const SingleLayerCrossoverRow& row = single_layer_crossover(tolerance);
      c = row.crossover;
      whose = row.measured ? "the single layer's measured FMM/direct crossover"
                           : "the single layer's FMM/direct crossover (extrapolated: direct was faster at every measured size)";
    } else {
      c = stresslet_crossover(tolerance);
      whose = "the stresslet FMM's FMM/direct crossover (fmm/calibration.hpp)";
    }
    const bool direct = below_crossover(static_cast<double>(n_src), static_cast<double>(n_trg), static_cast<double>(c));
    b = direct ? FarFieldBackend::Direct : FarFieldBackend::Fmm;
    why = fmt::format("auto: {} sources × {} targets is {} {} at tolerance {:g} ({} points)", n_src, n_trg,
                      direct ? "below" : "above", whose, tolerance, c);
  } else {
    b = requested == BackendRequest::Fmm ? FarFieldBackend::Fmm : FarFieldBackend::Direct;
    why = fmt::format("forced by the scene (fluid.backend = \"{}\")", to_string(requested));
  }
  // The double layer decides its precision per application (double_layer.cpp: set-up in double,
  // inexact GMRES steps may take single-precision pairs); the reason names the back end only.
  // (The FMM's near field: FarField, which knows the FMM's own tolerance.)
  if (kernel == FarFieldKernel::SingleLayer && b == FarFieldBackend::Direct && uses_mixed_precision(tolerance))
    why += fmt::format("; pairs in single precision, sums in double (tolerance >= {:g})", kMixedPrecisionTolerance);
  if (reason) *reason = why;
  return b;
}

bool double_layer_set_up_direct(BackendRequest requested, FarFieldBackend chosen, Eigen::Index n_sources, Eigen::Index n_targets,
                                double tolerance, std::string* reason) {
  if (requested != BackendRequest::Auto || chosen != FarFieldBackend::Fmm) return false;
  const double c = kDirectSetUpCrossoverFactor * static_cast<double>(stresslet_crossover(tolerance));
  const bool direct = below_crossover(static_cast<double>(n_sources), static_cast<double>(n_targets), c);
  if (direct && reason) *reason += fmt::format("; its set-up pass (four densities) direct, below {:.0f} points", c);
  return direct;
}

}  // namespace capsflow
