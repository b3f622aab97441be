#pragma once
// The far field of a layer operator (docs/boundary-integral.md §4.2.1, §4.3, §4.7.3), one component
// for both: the single layer's (Kernel = fmm::Stokeslet: a source carries a force) and the double
// layer's (fmm::Stresslet: a source carries its weighted normal ñ; the density the operator sums
// is (u(y), ñ) per source).
//   sources  — the far-field rule's three points on every element, weights 1/6 of the Jacobian:
//              the edge midpoints on flat facets, where the two sides of an edge are one source
//              (one per edge: 3N sources for N nodes), or the 3-point Gauss rule on curved elements
//              (three per element, 6N). Element e's point k is slot 3e + k (near_field.hpp).
//   back end — the FMM or the direct sum, chosen once for the operator's kernel, source and target
//              counts and tolerance (choose_backend, backend_choice.hpp); each FMM is set up on the
//              current sources and targets on its first evaluation after they changed.
//   check    — the same sum again by a direct sum in full double precision, compared node by node
//              (LayerOptions::verify_every): the fast paths it checks (FMM, one-Newton rsqrt,
//              single-precision pairs) are not shared by the reference.
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "capsflow/core/bie/backend_choice.hpp"
#include "capsflow/core/bie/boundary_surface.hpp"
#include "capsflow/core/bie/layer_options.hpp"
#include "capsflow/core/bie/near_field.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {
namespace fmm {
template <class K>
class Fmm;
}  // namespace fmm

// The far field of one evaluation against its direct re-summation: the largest and the RMS node
// difference, both relative to the largest directly summed far-field value.
struct FarFieldCheck {
  long evaluation = 0;  // which evaluation (0-based, counted by the operator)
  double max_relative = 0, rms_relative = 0;
};

// An operator's direct checks so far (LayerOptions::verify_every): how many, the latest, the one
// with the largest max difference, the largest RMS, and how many exceeded the tolerance.
struct FarFieldCheckLog {
  long checks = 0, above_tolerance = 0;
  FarFieldCheck last, worst;
  double worst_rms = 0;
  void add(const FarFieldCheck& c, double tolerance);
};

// One check: n target values of `dim` components as summed (far) against the direct re-summation
// (ref). The difference at a target is the Euclidean norm of its components' differences (a
// symmetric matrix given by its 6 upper entries, xx yy zz xy xz yz, counts its off-diagonal
// entries twice: the Frobenius norm); max and RMS over the targets, both relative to the largest
// reference norm (a zero reference gives 0: agreement, not 0/0).
FarFieldCheck compare_far_field(const double* far, const double* ref, std::size_t n, int dim, long evaluation);

// How a direct sum treats its pairs.
enum class DirectPairs {
  Exact,   // double precision, pairs at r = 0 skipped: any targets (the checks' reference, points off the surface)
  Fast,    // one Newton step after the hardware rsqrt (≤ 6e-9 per pair, ~1e-9 on the sum; far below the
           // smallest tolerance a scene accepts, 1e-8) and no r = 0 test: targets that never coincide
           // with a source, such as the nodes (edge midpoints and Gauss points never do); 15–20 %
           // faster than Exact
  Single,  // single-precision pairs, sums in double (fmm/direct_sum_mixed.hpp; AVX-512 or AVX2 builds), at the nodes
};

template <class Kernel>
class FarField {
 public:
  static constexpr int kMainFmm = 0;  // the FMM at the operator's tolerance (backend Fmm)

  // The far field of a surface of n_elements elements (its edges: `lists`) under the options'
  // rule, at n_targets targets, summed with `threads` OpenMP threads; the back end chosen for
  // this kernel (its main FMM asked for the operator's tolerance: kFmmToleranceMargin × tolerance
  // for the Stokeslet, double_layer_fmm_tolerance for the stresslet).
  FarField(const NearFieldLists& lists, Eigen::Index n_elements, Eigen::Index n_targets, const LayerOptions& opt, int threads);
  ~FarField();
  FarField(FarField&&) noexcept;
  FarField(const FarField&) = delete;
  FarField& operator=(const FarField&) = delete;

  // Sources.
  FarFieldRule rule() const { return rule_; }
  const double* rule_point(int k) const { return bary_[k]; }  // barycentrics of point k on every element
  Eigen::Index sources() const { return static_cast<Eigen::Index>(slots_.size()); }
  const std::array<int, 2>& slots(Eigen::Index source) const { return slots_[static_cast<std::size_t>(source)]; }
  // Places the sources on the surface x. For every element e (T: e about its vertex 0) and rule
  // point k, value(T, e, l, w, y, v) writes the point's position y and value v (3 each) from its
  // barycentrics l and weight w; per_element(T, e) follows in the same loop (an operator's own rule
  // points of e). Then each source takes its first slot's position and the sum of its slots'
  // values, and its second slot moves to that position, so that an operator's near field
  // subtracts exactly the term the far field added.
  template <class PointValue, class PerElement>
  void place(const Points& x, const BoundarySurface& surface, PointValue&& value, PerElement&& per_element);
  const double* slot_position(std::size_t slot) const { return &slot_y_[3 * slot]; }
  const double* slot_value(std::size_t slot) const { return &slot_v_[3 * slot]; }
  const std::vector<double>& slot_positions() const { return slot_y_; }  // 3 per slot
  const std::vector<double>& slot_values() const { return slot_v_; }
  const double* positions() const { return src_.data(); }  // 3 per source
  const double* values() const { return src_v_.data(); }   // 3 per source: its slots' summed values

  // Targets (copied).
  void set_targets(const double* targets, Eigen::Index n);
  const double* targets() const { return targets_.data(); }
  Eigen::Index n_targets() const { return static_cast<Eigen::Index>(targets_.size() / 3); }

  // The back end, and the accuracy it promises relative to max |v| (the options' fmm_tolerance
  // where it sums by the FMM and one is given, else their tolerance).
  FarFieldBackend backend() const { return backend_; }
  double tolerance() const { return tolerance_; }
  const std::string& reason() const { return reason_; }
  // The stresslet's only: whether the double layer's set-up pass (four densities) sums directly
  // although the iterations use the FMM (double_layer_set_up_direct, backend_choice.hpp).
  bool set_up_directly() const { return set_up_directly_; }
  int fmm_order(int fmm = kMainFmm) const;  // 0 without that FMM (the direct back end)
  int fmm_leaf_size() const;                // the main FMM's points per leaf; 0 without it
  // A further FMM of this kernel at `tolerance` (the options' forced order and leaf size, if any);
  // its handle for evaluate().
  int add_fmm(double tolerance);
  // out = the sum of `sets` densities (Kernel::src_dim per source each, one set after the other;
  // outputs likewise) at the targets by that FMM.
  void evaluate(int fmm, const double* density, double* out, int sets = 1);
  // out = the direct sum of Pair (the kernel, or another pair formula with the same sources) at
  // the targets, or at n other points.
  template <class Pair = Kernel>
  void direct(const double* density, double* out, DirectPairs pairs) const;
  template <class Pair = Kernel>
  void direct(const double* density, const double* targets, std::size_t n, double* out, DirectPairs pairs) const;

  // Checks (verify_every): whether the operator's evaluation number `evaluation` is checked; the
  // far field `far` of `density` (Pair at the targets) against the Exact direct sum; the log.
  bool check_due(long evaluation) const { return verify_every_ > 0 && evaluation % verify_every_ == 0; }
  template <class Pair = Kernel>
  FarFieldCheck compare_with_direct(const double* density, const double* far, long evaluation);
  void record(const FarFieldCheck& c) { checks_.add(c, tolerance_); }
  const FarFieldCheckLog& checks() const { return checks_; }

 private:
  struct Pass;  // an FMM and whether it is set up on the current sources and targets
  void sum_slots();  // each source from its slots (inside place()'s parallel region)
  void sources_moved();

  FarFieldRule rule_;
  const double (*bary_)[3];
  std::vector<std::array<int, 2>> slots_;  // per source: its slots, the second −1 when alone
  Eigen::Index n_elements_;
  int threads_, verify_every_;
  double tolerance_;
  std::vector<double> slot_y_, slot_v_, src_, src_v_, targets_;
  FarFieldBackend backend_;
  std::string reason_;
  bool set_up_directly_ = false;
  int fmm_order_forced_, fmm_leaf_size_forced_;
  std::vector<Pass> fmms_;
  FarFieldCheckLog checks_;
  std::vector<double> reference_;  // the checks' direct sums
};

template <class Kernel>
template <class PointValue, class PerElement>
void FarField<Kernel>::place(const Points& x, const BoundarySurface& surface, PointValue&& value, PerElement&& per_element) {
  const Eigen::Index m = n_elements_;
#pragma omp parallel num_threads(threads_)
  {
#pragma omp for schedule(static)
    for (Eigen::Index e = 0; e < m; ++e) {
      const QuadraticTriangle T = surface.element(x, e, 0);
      for (int k = 0; k < 3; ++k) {
        const std::size_t slot = static_cast<std::size_t>(3 * e + k);
        value(T, e, bary_[k], 1.0 / 6.0, &slot_y_[3 * slot], &slot_v_[3 * slot]);
      }
      per_element(T, e);
    }
    sum_slots();
  }
  sources_moved();
}

}  // namespace capsflow
