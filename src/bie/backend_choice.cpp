#include "capsflow/core/bie/backend_choice.hpp"

#include <fmt/core.h>

#include "capsflow/fmm/calibration.hpp"
#include "capsflow/fmm/direct_sum_mixed.hpp"

namespace capsflow {

namespace {
// Single-precision pairs (max relative error ~5e-7, fmm/direct_sum_mixed.hpp) leave a 20x margin
// from this tolerance on.
constexpr double kMixedPrecisionTolerance = 1e-5;
}  // namespace

bool uses_mixed_precision(FarFieldBackend b, double tolerance) {
  // Single-precision pairs (max relative error ~5e-7, fmm/direct_sum_mixed.hpp) whenever the
  // tolerance leaves a 20x margin; "direct" at tighter tolerances stays in double.
  return fmm::kMixedPrecisionDirectSum && b == FarFieldBackend::Direct && tolerance >= kMixedPrecisionTolerance;
}

FarFieldBackend choose_backend(BackendRequest requested, Eigen::Index n_sources, Eigen::Index n_targets, double tolerance,
                               std::string* reason) {
  const std::size_t n_src = static_cast<std::size_t>(n_sources), n_trg = static_cast<std::size_t>(n_targets);
  std::string why;
  FarFieldBackend b;
  if (requested == BackendRequest::Auto) {
    const bool direct = fmm::prefer_direct(n_src, n_trg, tolerance);
    b = direct ? FarFieldBackend::Direct : FarFieldBackend::Fmm;
    why = fmt::format("auto: {} sources × {} targets is {} the measured FMM/direct crossover at tolerance {:g} ({} points)",
                      n_src, n_trg, direct ? "below" : "above", tolerance, fmm::direct_crossover(tolerance));
  } else {
    b = requested == BackendRequest::Fmm ? FarFieldBackend::Fmm : FarFieldBackend::Direct;
    why = fmt::format("forced by the scene (fluid.backend = \"{}\")", to_string(requested));
  }
  if (b == FarFieldBackend::Direct && uses_mixed_precision(b, tolerance))
    why += fmt::format("; pairs in single precision, sums in double (tolerance >= {:g})", kMixedPrecisionTolerance);
  if (reason) *reason = why;
  return b;
}

}  // namespace capsflow
