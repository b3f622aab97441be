#include "capsflow/core/bie/far_field.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>

#include <fmt/core.h>

#include "capsflow/core/bie/quadrature.hpp"
#include "capsflow/core/bie/stresslet_pair.hpp"
#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/direct_sum_mixed.hpp"
#include "capsflow/fmm/fmm.hpp"
#include "capsflow/fmm/stokeslet.hpp"
#include "capsflow/fmm/stresslet.hpp"

namespace capsflow {

void FarFieldCheckLog::add(const FarFieldCheck& c, double tolerance) {
  last = c;
  ++checks;
  if (checks == 1 || c.max_relative > worst.max_relative) worst = c;
  worst_rms = std::max(worst_rms, c.rms_relative);
  if (c.max_relative > tolerance) ++above_tolerance;
}

FarFieldCheck compare_far_field(const double* far, const double* ref, std::size_t n, int dim, long evaluation) {
  double max_ref = 0, max_diff = 0, sum_sq = 0;
  for (std::size_t i = 0; i < n; ++i) {
    double d2 = 0, r2 = 0;
    for (int k = 0; k < dim; ++k) {
      const double w = dim == 6 && k >= 3 ? 2.0 : 1.0;  // a symmetric matrix's off-diagonal entries count twice
      const double d = far[dim * i + k] - ref[dim * i + k];
      d2 += w * d * d;
      r2 += w * ref[dim * i + k] * ref[dim * i + k];
    }
    max_ref = std::max(max_ref, std::sqrt(r2));
    max_diff = std::max(max_diff, std::sqrt(d2));
    sum_sq += d2;
  }
  FarFieldCheck c;
  c.evaluation = evaluation;
  c.max_relative = max_ref > 0 ? max_diff / max_ref : 0.0;
  c.rms_relative = max_ref > 0 ? std::sqrt(sum_sq / static_cast<double>(n)) / max_ref : 0.0;
  return c;
}

template <class Kernel>
struct FarField<Kernel>::Pass {
  std::unique_ptr<fmm::Fmm<Kernel>> fmm;
  bool ready = false;  // set up on the current sources and targets
};

namespace {
template <class Kernel>
constexpr bool kStokeslet = std::is_same_v<Kernel, fmm::Stokeslet>;
}  // namespace

template <class Kernel>
FarField<Kernel>::FarField(const NearFieldLists& lists, Eigen::Index n_elements, Eigen::Index n_targets, const LayerOptions& opt,
                           int threads)
    : rule_(far_field_rule(opt)),
      bary_(rule_ == FarFieldRule::EdgeMidpoints ? kEdgeMidpointBary : kGaussBary),
      slots_(far_field_source_slots(lists, n_elements, rule_ == FarFieldRule::EdgeMidpoints)),
      n_elements_(n_elements),
      threads_(threads),
      verify_every_(opt.verify_every),
      tolerance_(opt.tolerance),
      slot_y_(9 * static_cast<std::size_t>(n_elements)),
      slot_v_(9 * static_cast<std::size_t>(n_elements)),
      src_(3 * slots_.size()),
      src_v_(3 * slots_.size()),
      fmm_order_forced_(opt.fmm_order),
      fmm_leaf_size_forced_(opt.fmm_leaf_size) {
  const FarFieldKernel kernel = kStokeslet<Kernel> ? FarFieldKernel::SingleLayer : FarFieldKernel::DoubleLayer;
  backend_ = choose_backend(opt.backend, kernel, sources(), n_targets, opt.tolerance, &reason_);
  if (backend_ != FarFieldBackend::Fmm) return;
  tolerance_ = fmm_promise(opt);
  if (tolerance_ != opt.tolerance) reason_ += fmt::format("; the FMM at tolerance {:g}", tolerance_);
  if (kStokeslet<Kernel> && uses_mixed_precision(tolerance_))
    reason_ += "; its direct near field in single-precision pairs, sums in double";
  // The FMM calibration is in relative L2 error over the targets; capsflow promises the tolerance
  // relative to max |v| at every node (max norm), so the Stokeslet's FMM is asked for a safety
  // margin; the stresslet's order follows from the error relative to the density (backend_choice.hpp).
  add_fmm(kStokeslet<Kernel> ? kFmmToleranceMargin * tolerance_ : double_layer_fmm_tolerance(tolerance_));
  if constexpr (!kStokeslet<Kernel>)
    set_up_directly_ = double_layer_set_up_direct(opt.backend, backend_, sources(), n_targets, opt.tolerance, &reason_);
}

template <class Kernel>
FarField<Kernel>::~FarField() = default;
template <class Kernel>
FarField<Kernel>::FarField(FarField&&) noexcept = default;

template <class Kernel>
void FarField<Kernel>::sum_slots() {
  // Called inside place()'s parallel region: the slots are written (the loop before has its barrier).
  const Eigen::Index ns = sources();
#pragma omp for schedule(static)
  for (Eigen::Index s = 0; s < ns; ++s) {
    const std::size_t first = static_cast<std::size_t>(slots_[static_cast<std::size_t>(s)][0]);
    const int second = slots_[static_cast<std::size_t>(s)][1];
    for (std::size_t d = 0; d < 3; ++d) {
      const std::size_t k = 3 * static_cast<std::size_t>(s) + d;
      src_[k] = slot_y_[3 * first + d];
      src_v_[k] = slot_v_[3 * first + d];
      if (second < 0) continue;
      src_v_[k] += slot_v_[3 * static_cast<std::size_t>(second) + d];
      slot_y_[3 * static_cast<std::size_t>(second) + d] = slot_y_[3 * first + d];
    }
  }
}

template <class Kernel>
void FarField<Kernel>::sources_moved() {
  for (Pass& p : fmms_) p.ready = false;
}

template <class Kernel>
void FarField<Kernel>::set_targets(const double* targets, Eigen::Index n) {
  targets_.assign(targets, targets + 3 * n);
  sources_moved();
}

template <class Kernel>
int FarField<Kernel>::fmm_order(int fmm) const {
  return fmm >= 0 && fmm < static_cast<int>(fmms_.size()) ? fmms_[static_cast<std::size_t>(fmm)].fmm->order() : 0;
}

template <class Kernel>
int FarField<Kernel>::fmm_leaf_size() const {
  return fmms_.empty() ? 0 : fmms_.front().fmm->leaf_size();
}

template <class Kernel>
int FarField<Kernel>::add_fmm(double tolerance) {
  fmm::FmmOptions o;
  o.tolerance = tolerance;
  o.order = fmm_order_forced_;
  o.leaf_size = fmm_leaf_size_forced_;
  o.threads = threads_;
  // the single layer's FMM sums its direct near field in single precision from tolerance 1e-5
  o.single_precision_pairs = kStokeslet<Kernel> && uses_mixed_precision(tolerance_);
  fmms_.push_back(Pass{std::make_unique<fmm::Fmm<Kernel>>(o)});
  return static_cast<int>(fmms_.size()) - 1;
}

template <class Kernel>
void FarField<Kernel>::evaluate(int fmm, const double* density, double* out, int sets) {
  Pass& p = fmms_.at(static_cast<std::size_t>(fmm));
  if (!p.ready) p.fmm->setup(src_.data(), slots_.size(), targets_.data(), targets_.size() / 3);
  p.ready = true;
  p.fmm->evaluate(density, out, sets);
}

template <class Kernel>
template <class Pair>
void FarField<Kernel>::direct(const double* density, double* out, DirectPairs pairs) const {
  direct<Pair>(density, targets_.data(), targets_.size() / 3, out, pairs);
}

template <class Kernel>
template <class Pair>
void FarField<Kernel>::direct(const double* density, const double* targets, std::size_t n, double* out, DirectPairs pairs) const {
  const std::size_t ns = slots_.size();
  switch (pairs) {
    case DirectPairs::Exact:
      fmm::direct_sum<Pair>(src_.data(), ns, density, targets, n, out, threads_);
      break;
    case DirectPairs::Fast:
      fmm::direct_sum<Pair, 1, false>(src_.data(), ns, density, targets, n, out, threads_);
      break;
    case DirectPairs::Single:  // the kernel's own pairs only (fmm/direct_sum_mixed.hpp)
      if constexpr (std::is_same_v<Pair, Kernel>)
        fmm::direct_sum_mixed<Pair>(src_.data(), ns, density, targets, n, out, threads_);
      else
        throw std::logic_error("far field: single-precision pairs are summed for the kernel only");
      break;
  }
}

template <class Kernel>
template <class Pair>
FarFieldCheck FarField<Kernel>::compare_with_direct(const double* density, const double* far, long evaluation) {
  const std::size_t n = targets_.size() / 3;
  reference_.resize(static_cast<std::size_t>(Pair::trg_dim) * n);
  direct<Pair>(density, reference_.data(), DirectPairs::Exact);
  return compare_far_field(far, reference_.data(), n, Pair::trg_dim, evaluation);
}

template class FarField<fmm::Stokeslet>;
template class FarField<fmm::Stresslet>;
template void FarField<fmm::Stokeslet>::direct<fmm::Stokeslet>(const double*, double*, DirectPairs) const;
template void FarField<fmm::Stresslet>::direct<fmm::Stresslet>(const double*, double*, DirectPairs) const;
template void FarField<fmm::Stresslet>::direct<StressletAndNormalPair>(const double*, double*, DirectPairs) const;
template void FarField<fmm::Stresslet>::direct<StressletNormalPair>(const double*, double*, DirectPairs) const;
template void FarField<fmm::Stresslet>::direct<StressletNormalPair>(const double*, const double*, std::size_t, double*,
                                                                   DirectPairs) const;
template FarFieldCheck FarField<fmm::Stokeslet>::compare_with_direct<fmm::Stokeslet>(const double*, const double*, long);
template FarFieldCheck FarField<fmm::Stresslet>::compare_with_direct<fmm::Stresslet>(const double*, const double*, long);
template FarFieldCheck FarField<fmm::Stresslet>::compare_with_direct<StressletNormalPair>(const double*, const double*, long);

}  // namespace capsflow
