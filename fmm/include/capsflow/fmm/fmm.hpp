#pragma once
// capsflow::fmm::Fmm<Kernel> — kernel-independent FMM (Ying, Biros & Zorin 2004).
//
// Three lifetimes:
//   1. Operators (per kernel and order): built in the constructor, or loaded from the disk cache
//      (<cache_dir>/<kernel>_p<order>_f64.bin). Can be shared between Fmm objects.
//   2. Tree + lists: setup(src, n_src, trg, n_trg) — call every time the points move.
//   3. Evaluation: evaluate(density, out, n_densities) — repeat with new densities.
// Points are xyz-interleaved (x0,y0,z0,x1,...); densities Kernel::src_dim per source, outputs
// Kernel::trg_dim per target, all in the caller's order; outputs are OVERWRITTEN. The sum is the
// one of direct_sum (see the kernel header for its conventions; pairs at distance 0 skipped).
// Kernels with their own equivalent kernels (equivalent.hpp; the Stresslet) run the passes on
// those: Kernel itself only in P2M, P2L and the direct near field.
// Accuracy: options.tolerance (relative L2 error against direct summation) is mapped to an
// order by the kernel's committed calibration table (calibration.hpp); options.order > 0 forces p.
#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "capsflow/fmm/calibration.hpp"
#include "capsflow/fmm/operators.hpp"
#include "capsflow/fmm/tree.hpp"

namespace capsflow::fmm {

struct FmmOptions {
  double tolerance = 1e-6;  ///< requested relative L2 accuracy; mapped to an order (calibration.hpp)
  int order = 0;            ///< > 0 forces the order p (>= 2), overriding tolerance
  int leaf_size = 0;        ///< max points (sources or targets) per leaf; 0 = tuned default
  std::string cache_dir;    ///< "" = $CAPSFLOW_CACHE_DIR, $XDG_CACHE_HOME/capsflow, ~/.cache/capsflow
  int threads = 0;          ///< 0 = OpenMP default
  /// false (default): for orders <= 8 (errors >= 1e-7) the near field uses one Newton step after
  /// the hardware rsqrt (<= 6e-9 relative per pair, ~16 % faster). true: full double accuracy.
  bool exact_near_field = false;
  /// true: the direct near field's pairs (U list, and the W and X lists where summed directly) in
  /// single precision with double sums (p2p_mixed.hpp: ~4e-7 in L2 on random sums), for
  /// tolerances ≥ 1e-5; one density per call only (several share the double pairs). Ignored
  /// without a single-precision vector type and with exact_near_field.
  bool single_precision_pairs = false;
};

/// Seconds spent in each phase by the last setup() / evaluate() (evaluate: all its densities).
struct FmmTimings {
  double tree = 0;      ///< setup: sort, octree, interaction lists
  double p2m = 0;       ///< leaf sources -> upward check -> UE
  double m2m = 0;       ///< child UE -> parent UE
  double m2l = 0;       ///< V list: FFTs + Hadamard products
  double m2l_fft = 0;   ///<   of which forward + inverse FFTs (thread 0's share)
  double m2l_hadamard = 0;  ///<   of which Hadamard products (thread 0's share)
  double x_list = 0;    ///< X list: P2L (or direct)
  double l2l = 0;       ///< downward check -> DE, parent DE -> child
  double p2p = 0;       ///< U list + W list (M2P or direct) + direct X
  double l2p = 0;       ///< DE -> targets
  double other = 0;     ///< gather/scatter, scaling
  double setup_total = 0;
  double eval_total = 0;
};

template <class Kernel>
class Fmm {
 public:
  using Up = typename Operators<Kernel>::Up;      ///< upward equivalent kernel (equivalent.hpp)
  using Down = typename Operators<Kernel>::Down;  ///< downward equivalent kernel
  explicit Fmm(const FmmOptions& opt);
  /// Share operators built elsewhere (same kernel); opt.order/tolerance are then ignored.
  Fmm(const FmmOptions& opt, std::shared_ptr<const Operators<Kernel>> ops);

  void setup(const double* src, std::size_t n_src, const double* trg, std::size_t n_trg);
  /// n_densities density vectors, one after the other (src_dim·n_src each); outputs likewise.
  /// Densities are evaluated in groups of up to kMaxSharedDensities that share every pass: one
  /// tree walk, each pair's distance and 1/|r| in the P2P/P2M/L2P loops, each operator matrix
  /// streamed once for all of them (GEMMs with nd× more columns), each M2L kernel block loaded
  /// once. Each density gets the same arithmetic as a single call (results equal to rounding).
  void evaluate(const double* density, double* out, int n_densities = 1);

  int order() const { return ops_->order(); }
  int leaf_size() const { return leaf_size_; }
  int threads() const { return threads_; }
  const FmmTimings& timings() const { return t_; }
  const Tree& tree() const { return tree_; }
  const Operators<Kernel>& operators() const { return *ops_; }

 private:
  int group_size(int n_densities) const;
  void evaluate_group(const double* density, double* out, int nd);
  void upward();
  void downward_checks();
  void downward();
  void near_field();
  void local_to_targets();

  FmmOptions opt_;
  // near field with one Newton step (6e-9 per pair) for orders whose error is >= 1e-7 (p <= 8)
  static constexpr int kFastRsqrtMaxOrder = 8;
  bool fast_rsqrt_ = false;
  bool single_pairs_ = false;  // opt_.single_precision_pairs where it applies
  int leaf_size_ = 0, threads_ = 1;
  std::shared_ptr<const Operators<Kernel>> ops_;
  Tree tree_;
  bool has_setup_ = false;
  std::size_t n_src_ = 0, n_trg_ = 0;
  // per-evaluation data (sorted order, structure of arrays)
  // nd_ densities of one group share every pass (see evaluate()).
  int nd_ = 1;
  std::vector<double> f_;   // nd·src_dim arrays of n_src (density-major, then component)
  std::vector<double> u_;   // nd·trg_dim arrays of n_trg
  // per node nd surface vectors, column (node·nd + d): ue_ of the upward equivalent kernel's
  // src_dim·nsurf, de_ of the downward one's, cu_ / rc_ of trg_dim·nsurf
  std::vector<double> ue_, cu_, rc_, de_;
  std::vector<char> x_direct_;             // per node: X list evaluated directly
  std::vector<double> sspec_, tspec_;      // M2L spectra of one level (reused)
  std::vector<double> pinv_work_;          // singular coordinates of one level (pinv factors)
  FmmTimings t_;
};

}  // namespace capsflow::fmm

#include "capsflow/fmm/fmm_impl.hpp"
