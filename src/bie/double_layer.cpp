#include "capsflow/core/bie/double_layer.hpp"

#include <omp.h>

#include <algorithm>
#include <iterator>
#include <stdexcept>

#include "capsflow/core/bie/stresslet_pair.hpp"
#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/direct_sum_mixed.hpp"
#include "capsflow/fmm/fmm.hpp"
#include "capsflow/fmm/stresslet.hpp"

namespace capsflow {

namespace {
constexpr double kInv8Pi = fmm::Stresslet::scale();
// Single-precision pairs err by ~1e-7 of the output in L2 (≤ 4e-7 of its largest entry;
// fmm/direct_sum_mixed.hpp, tests/fmm/test_kernels.cpp); taken from an allowance of 1e-3 relative
// to the input. Considered and rejected: from 1e-5 under GMRES's margin of 1 the first Krylov step
// of most stages summed in single precision too, and GMRES needed 9 % more steps (λ = 0.01, Fig. 4
// at 20 480 elements to γ̇t = 0.1: 240 against 221).
constexpr double kMixedPrecisionAllowedError = 1e-3;
// With the FMM, inexact steps take FMMs of lower orders: from each allowance (relative to the
// density) the order that keeps a quarter of it in L2 and all of it in max (double_layer_fmm_tolerance;
// p = 4, 5, 6, 7, measured 7.8e-4 / 3.2e-3, 4.0e-4 / 2.4e-3, 2.7e-5 / 7.9e-5 and 1.4e-6 / 7.3e-6), and
// apply() returns that quarter as the error it committed (gmres.hpp's a-posteriori bound). At
// 81 920 elements on the Fig. 4 capsule one application costs 0.076, 0.10, 0.14 and 0.20 s at
// p = 4, 5, 6, 7 against 0.27 s at the exact p = 9 (2 threads, set-up included; perf/RESULTS.md
// §1.6). GMRES allows target / ‖r_k‖ (gmres.hpp), so that most steps take p = 4.
constexpr double kInexactFmmAllowedErrors[] = {1e-2, 5e-3, 1e-3, 1e-4};  // loosest first
constexpr double kInexactL2Share = 0.25;  // a tier's L2 error bound, as a share of its allowance
// Single-precision pairs' L2 error relative to the density, 10× the measured 1e-7 (above).
constexpr double kMixedPrecisionL2Error = 1e-6;
// D̃[1]'s reused error term (§4.7.5): the drift a reuse may have, as a share of the tolerance (the
// FMM's own margin, kFmmToleranceMargin). Every set-up that could reuse measures the drift exactly
// at a sample of nodes (direct sums) and refreshes when it exceeds half that allowance: the other
// half covers the nodes between the samples (the drift is smooth over the surface: E follows the
// local geometry) and the refresh pass's own error, which its order keeps below a quarter of the
// allowance (so that E's extrapolation does not amplify FMM noise). A guard for what the sample
// cannot see: a node whose corner value moved by more than kCornerJump in its frame since the
// refresh, and by more than kCornerOverSampled times the most any sampled node's did (a local jump
// between the samples, not the whole surface's motion, which the sample measures), forces a refresh.
constexpr double kIdentityDriftShare = 0.25;
constexpr double kSampledDriftShare = 0.5;
constexpr double kRefreshPassShare = 0.25;
constexpr double kCornerJump = 1e-3;
constexpr double kCornerOverSampled = 2.0;
// The sample: this many nodes spread over the surface (every k-th in breadth-first order); at
// 81 920 elements their direct sums cost ~2 % of a λ = 5 evaluation.
constexpr int kIdentitySamples = 512;
// How far along the line through the last two refreshes E may be extrapolated, in units of their
// distance (the fit's s, clamped: beyond, the refresh pass's noise would be amplified).
constexpr double kExtrapolationRange[2] = {-1.0, 3.0};
// Along two secants (E1 − E0, E0 − E−1): coefficients within ±6 (noise amplified at most ~10×;
// what it does amplify the sample sees), and only where the secants are independent.
constexpr double kQuadraticRange[2] = {-6.0, 6.0};
constexpr double kSecantsIndependent = 1e-6;
constexpr size_t kRecord = 24;  // per node: E1, C1, E0, E−1 (6 each, symmetric)

inline void add(double* b, double c, const Mat3& m) {
  b[0] += c * m(0, 0), b[1] += c * m(1, 1), b[2] += c * m(2, 2);
  b[3] += c * m(0, 1), b[4] += c * m(0, 2), b[5] += c * m(1, 2);
}
inline Mat3 sym_matrix(const double* b) {
  Mat3 m;
  m << b[0], b[3], b[4], b[3], b[1], b[5], b[4], b[5], b[2];
  return m;
}
inline void sym_store(const Mat3& m, double* b) {
  b[0] = m(0, 0), b[1] = m(1, 1), b[2] = m(2, 2), b[3] = 0.5 * (m(0, 1) + m(1, 0)), b[4] = 0.5 * (m(0, 2) + m(2, 0)),
  b[5] = 0.5 * (m(1, 2) + m(2, 1));
}
// A node's reused error term in its local frame: E1 + s (E1 − E0) + s2 (E0 − E−1), from its record
// (E1, C1, E0, E−1).
inline Mat3 extrapolated_error(const double* record, double s, double s2 = 0) {
  const Mat3 E1 = sym_matrix(record);
  Mat3 E = E1;
  if (s != 0) E += s * (E1 - sym_matrix(record + 12));
  if (s2 != 0) E += s2 * (sym_matrix(record + 12) - sym_matrix(record + 18));
  return E;
}
inline Vec3 sym_times(const double* b, const double* u) {
  return {b[0] * u[0] + b[3] * u[1] + b[4] * u[2], b[3] * u[0] + b[1] * u[1] + b[5] * u[2],
          b[4] * u[0] + b[5] * u[1] + b[2] * u[2]};
}
// A rule point (barycentrics l, weight w of the reference triangle) of an element: position and w N.
inline void rule_point(const QuadraticTriangle& T, const double* l, double w, double* y, double* n) {
  const Vec3 p = T.position(l[1], l[2]), a = w * T.area_normal(l[1], l[2]);
  for (int d = 0; d < 3; ++d) y[d] = p[d], n[d] = a[d];
}
}  // namespace

DoubleLayer::DoubleLayer(const Triangles& triangles, Eigen::Index n_nodes, const DoubleLayerOptions& opt)
    : tri_(triangles),
      n_nodes_(n_nodes),
      opt_(opt),
      threads_(layer_threads(opt)),
      far_rule_(far_field_rule(opt)),
      rule_(opt.singular_points),
      rule_u_(opt.singular_radial_points),
      lists_(triangles, n_nodes, near_ring_layers(opt), corrected_layers(opt, near_ring_layers(opt), kAutoDoubleLayerCorrectedLayers)),
      surface_(triangles, opt.geometry),
      source_slots_(far_field_source_slots(lists_, triangles.rows(), far_rule_ == FarFieldRule::EdgeMidpoints)) {
  backend_ = choose_backend(opt.backend, FarFieldKernel::DoubleLayer, far_field_sources(), n_nodes, opt.tolerance, &reason_);
  double fmm_tolerance = 0;  // the iterations' FMM's (the refresh pass's below takes its own if stricter)
  if (backend_ == FarFieldBackend::Fmm) {
    fmm_tolerance = double_layer_fmm_tolerance(opt.tolerance);
    fmm_ = std::make_unique<fmm::Fmm<fmm::Stresslet>>(fmm_options(fmm_tolerance));
    // From the strictest allowance on, each tier only where its order is lower than the next
    // stricter one's (no cheaper order to gain otherwise).
    int stricter_order = fmm_->order();
    for (size_t k = std::size(kInexactFmmAllowedErrors); opt.fmm_order <= 0 && k-- > 0;) {
      const double allowed = kInexactFmmAllowedErrors[k];
      const double tolerance = double_layer_fmm_tolerance(kInexactL2Share * allowed, allowed);
      const int order = fmm::order_for_tolerance<fmm::Stresslet>(tolerance);
      if (order >= stricter_order) continue;
      stricter_order = order;
      inexact_fmms_.insert(inexact_fmms_.begin(), InexactFmm{allowed, tolerance, order, nullptr});
    }
    direct_set_up_ = double_layer_set_up_direct(opt.backend, backend_, far_field_sources(), n_nodes, opt.tolerance, &reason_);
  }
  const size_t m = static_cast<size_t>(tri_.rows()), ns = source_slots_.size();
  slot_y_.resize(9 * m), slot_n_.resize(9 * m);
  if (lists_.corrected_layers() > lists_.ring_layers()) band_y_.resize(9 * m), band_n_.resize(9 * m);
  if (lists_.ring_layers() > 0) ring_y_.resize(21 * m), ring_n_.resize(21 * m);
  src_.resize(3 * ns), src_n_.resize(3 * ns), density_.resize(6 * ns);
  build_near_pattern();
  // The corner value is the flat polyhedron's: curved elements take the full pass on every set-up.
  // So does the direct back end: its pair loop costs the pair geometry for one density as for four
  // (measured at 5 120 elements: no gain); the FMM's cost follows the densities.
  reuse_ = !surface_.curved() && opt.reuse_identity_term && backend_ == FarFieldBackend::Fmm;
  if (reuse_) {
    fans_ = std::make_unique<CornerFans>(triangles, n_nodes);
    refreshed_.resize(kRecord * static_cast<size_t>(n_nodes)), corner_.resize(21 * static_cast<size_t>(n_nodes));
    const size_t stride = std::max<size_t>(1, node_order_.size() / kIdentitySamples);
    for (size_t k = 0; k < node_order_.size(); k += stride) samples_.push_back(node_order_[k]);
    sample_x_.resize(3 * samples_.size()), sample_far_.resize(6 * samples_.size()), sample_error_.resize(samples_.size());
    // The refresh pass at the order whose error (relative to the density, in max: the allowance's
    // norm) is a quarter of the allowance: its E is what the set-ups between reuse and extrapolate.
    const double refresh_max = kRefreshPassShare * kIdentityDriftShare * opt.tolerance;
    const double tolerance = double_layer_fmm_tolerance(refresh_max, refresh_max);
    if (opt.fmm_order <= 0 && tolerance < fmm_tolerance) fmm_refresh_ = std::make_unique<fmm::Fmm<fmm::Stresslet>>(fmm_options(tolerance));
  }
}

DoubleLayer::~DoubleLayer() = default;
fmm::FmmOptions DoubleLayer::fmm_options(double tolerance) const {
  fmm::FmmOptions o;
  o.tolerance = tolerance;
  o.order = opt_.fmm_order;  // > 0: every FMM at that order (and no tiers or refresh pass of their own)
  o.leaf_size = opt_.fmm_leaf_size;
  o.threads = threads_;
  return o;
}
int DoubleLayer::inexact_fmm_order() const {
  for (const InexactFmm& t : inexact_fmms_)
    if (t.allowed_error <= std::end(kInexactFmmAllowedErrors)[-1]) return t.order;
  return 0;
}
std::vector<DoubleLayer::InexactFmmUse> DoubleLayer::inexact_fmm_uses() const {
  std::vector<InexactFmmUse> uses;
  for (const InexactFmm& t : inexact_fmms_) uses.push_back({t.allowed_error, t.order, t.applications});
  return uses;
}
int DoubleLayer::fmm_order() const { return fmm_ ? fmm_->order() : 0; }
int DoubleLayer::refresh_fmm_order() const { return fmm_refresh_ ? fmm_refresh_->order() : fmm_order(); }
DoubleLayer::DoubleLayer(DoubleLayer&&) noexcept = default;

void DoubleLayer::build_near_pattern() {
  // Columns of node i: the vertices of its touching, ring and band elements; slots in list order.
  block_start_.assign(1, 0);
  slot_start_.assign(1, 0);
  std::vector<int> cols, listed;
  for (Eigen::Index i = 0; i < n_nodes_; ++i) {
    listed.clear();
    for (int e : lists_.touching(i)) listed.push_back(e);
    for (int e : lists_.ring(i)) listed.push_back(e);
    for (int e : lists_.band(i)) listed.push_back(e);
    cols.clear();
    for (int e : listed)
      for (int k = 0; k < 3; ++k) cols.push_back(tri_(e, k));
    std::sort(cols.begin(), cols.end());
    cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
    const int base = block_start_.back();
    block_col_.insert(block_col_.end(), cols.begin(), cols.end());
    block_start_.push_back(static_cast<int>(block_col_.size()));
    for (int e : listed)
      for (int k = 0; k < 3; ++k)
        slot_.push_back(base + static_cast<int>(std::lower_bound(cols.begin(), cols.end(), tri_(e, k)) - cols.begin()));
    slot_start_.push_back(static_cast<int>(slot_.size()));
  }
  block_.resize(6 * block_col_.size());
  diagonal_.resize(static_cast<size_t>(6 * n_nodes_));
  // The assembly visits the nodes breadth-first over the mesh: consecutive nodes are neighbours
  // and share most of their listed elements, whose rule points then stay in cache (in the
  // generator's numbering neighbours can be far apart: the assembly was memory-bound).
  std::vector<std::vector<int>> adjacent(static_cast<size_t>(n_nodes_));
  for (Eigen::Index e = 0; e < tri_.rows(); ++e)
    for (int k = 0; k < 3; ++k) adjacent[static_cast<size_t>(tri_(e, k))].push_back(tri_(e, (k + 1) % 3));
  std::vector<char> seen(static_cast<size_t>(n_nodes_), 0);
  node_order_.clear();
  for (Eigen::Index start = 0; start < n_nodes_; ++start) {  // every component
    if (seen[static_cast<size_t>(start)]) continue;
    seen[static_cast<size_t>(start)] = 1;
    node_order_.push_back(static_cast<int>(start));
    for (size_t head = node_order_.size() - 1; head < node_order_.size(); ++head)
      for (int j : adjacent[static_cast<size_t>(node_order_[head])])
        if (!seen[static_cast<size_t>(j)]) seen[static_cast<size_t>(j)] = 1, node_order_.push_back(j);
  }
}

void DoubleLayer::set_surface(const Points& x, const Points* u, Points* Du, bool on_trajectory) {
  if (x.rows() != n_nodes_) throw std::invalid_argument("double layer: positions must have one row per node");
  if ((u == nullptr) != (Du == nullptr) || (u && u->rows() != n_nodes_))
    throw std::invalid_argument("double layer: set_surface's first application needs u (one row per node) and Du");
  Stopwatch clock, total;
  x_ = x;
  for (InexactFmm& t : inexact_fmms_) t.ready = false;  // trees set up on the first inexact step that takes them
  fmm_ready_ = false;          // likewise the full-order FMM's, unless the set-up pass uses it
  surface_.update(x, threads_);
  const auto& far_bary = far_rule_ == FarFieldRule::EdgeMidpoints ? kEdgeMidpointBary : kGaussBary;
  const Eigen::Index m = tri_.rows(), ns = far_field_sources();
#pragma omp parallel num_threads(threads_)
  {
#pragma omp for schedule(static)
    for (Eigen::Index e = 0; e < m; ++e) {
      const QuadraticTriangle T = surface_.element(x, e, 0);
      for (int k = 0; k < 3; ++k) rule_point(T, far_bary[k], 1.0 / 6.0, &slot_y_[9 * e + 3 * k], &slot_n_[9 * e + 3 * k]);
      if (!band_y_.empty())
        for (int g = 0; g < 3; ++g) rule_point(T, kGaussBary[g], 1.0 / 6.0, &band_y_[9 * e + 3 * g], &band_n_[9 * e + 3 * g]);
      if (!ring_y_.empty())
        for (int p = 0; p < 7; ++p)
          rule_point(T, kDunavant7[p], 0.5 * kDunavant7[p][3], &ring_y_[21 * e + 3 * p], &ring_n_[21 * e + 3 * p]);
    }
    // Each source at its first slot's point with the sum of its slots' ñ (the two sides of an edge);
    // its other slot takes the same position, so that the near field subtracts the far field's term.
#pragma omp for schedule(static)
    for (Eigen::Index s = 0; s < ns; ++s) {
      const auto& sl = source_slots_[static_cast<size_t>(s)];
      for (int d = 0; d < 3; ++d) {
        src_[3 * s + d] = slot_y_[3 * sl[0] + d];
        src_n_[3 * s + d] = slot_n_[3 * sl[0] + d] + (sl[1] < 0 ? 0.0 : slot_n_[3 * sl[1] + d]);
        if (sl[1] >= 0) slot_y_[3 * sl[1] + d] = slot_y_[3 * sl[0] + d];
      }
    }
  }
  clock.lap(times_, Phase::BieSources);
  // The near blocks and their row sums first (diagonal_ = ½ I − the row sums): the sampled drift
  // needs them, and they do not depend on the far field.
  assemble_near_field(x);
  clock.lap(times_, Phase::BieNear);
  // D̃[1]: the far field of the unit constants (one pass of T(r)·ñ) plus the row sums — or, between
  // refreshes, C plus the reused error term (§4.7.5). Given u, its far field D̃[u] comes from the
  // same pass (the pair geometry computed once). Far-field points are interior to elements or edge
  // midpoints, never a node: no r = 0 test, one Newton step (≤ 6e-9 per pair), as for the single
  // layer's direct far field.
  const size_t n = static_cast<size_t>(n_nodes_);
  unit_far_.resize(6 * n);
  if (u) fill_far_densities(*u);
  // A surface whose far field is verified takes the FMM pass even where the set-up sums directly:
  // the check is of the FMM (set-up, operators, order) that every iteration on it uses.
  const bool verify_now = opt_.verify_every > 0 && setups_ % opt_.verify_every == 0;
  bool refresh = true, sample_called = false;
  if (reuse_) {
    corner_geometry(x);
    refresh = forced_refresh(on_trajectory, verify_now);
    extrapolation_ = extrapolation2_ = sampled_drift_ = 0;
    if (!refresh) {
      sample_identity_drift();
      refresh = sample_called = on_trajectory && sampled_drift_ > kSampledDriftShare * kIdentityDriftShare * opt_.tolerance;
      if (!refresh && on_trajectory) max_reused_drift_ = std::max(max_reused_drift_, sampled_drift_);
    }
    clock.lap(times_, Phase::BieSources);
  }
  if (!refresh) {
    // D̃[1] from C and the reused E: the far-field pass is the first application's alone.
    // Reuse implies the FMM back end.
    if (u) {
      Du->resize(n_nodes_, 3);
      fmm_->setup(src_.data(), static_cast<std::size_t>(ns), x_.data(), n);
      fmm_ready_ = true;
      fmm_->evaluate(density_.data(), Du->data());
    }
  } else if (fmm_ && (!direct_set_up_ || verify_now)) {
    // The FMM of the three unit constants (f = e_k, n = ñ), and of u, in one call, at the refresh
    // pass's order; T_ijk ñ_k is symmetric in i, j. A verified surface sums u by the iterations'
    // FMM instead, which the check is of.
    fmm::Fmm<fmm::Stresslet>& F = fmm_refresh_ ? *fmm_refresh_ : *fmm_;
    const bool u_here = u && !(verify_now && fmm_refresh_);
    F.setup(src_.data(), static_cast<std::size_t>(ns), x_.data(), n);
    fmm_ready_ = &F == fmm_.get();
    const int sets = u_here ? 4 : 3;
    std::vector<double> dens(6 * static_cast<size_t>(sets * ns)), out(3 * static_cast<size_t>(sets) * n);
    for (Eigen::Index s = 0; s < ns; ++s)
      for (int k = 0; k < 3; ++k) {
        double* d = &dens[6 * (static_cast<size_t>(k * ns + s))];
        for (int c = 0; c < 3; ++c) d[c] = c == k ? 1.0 : 0.0, d[3 + c] = src_n_[3 * s + c];
      }
    if (u_here) std::copy(density_.begin(), density_.end(), dens.begin() + 18 * static_cast<std::ptrdiff_t>(ns));
    F.evaluate(dens.data(), out.data(), sets);
    for (size_t i = 0; i < n; ++i) {
      auto col = [&](int k, int c) { return out[3 * (k * n + i) + static_cast<size_t>(c)]; };  // D̃[e_k]_c
      double* f = &unit_far_[6 * i];
      f[0] = col(0, 0), f[1] = col(1, 1), f[2] = col(2, 2);
      f[3] = 0.5 * (col(1, 0) + col(0, 1)), f[4] = 0.5 * (col(2, 0) + col(0, 2)), f[5] = 0.5 * (col(2, 1) + col(1, 2));
    }
    if (u) Du->resize(n_nodes_, 3);
    if (u_here) {
      std::copy(out.begin() + 9 * static_cast<std::ptrdiff_t>(n), out.end(), Du->data());
    } else if (u) {
      fmm_->setup(src_.data(), static_cast<std::size_t>(ns), x_.data(), n);
      fmm_ready_ = true;
      fmm_->evaluate(density_.data(), Du->data());
    }
  } else if (u) {
    std::vector<double> out(9 * n);
    fmm::direct_sum<StressletAndNormalPair, 1, false>(src_.data(), static_cast<std::size_t>(ns), density_.data(), x_.data(), n,
                                                      out.data(), threads_);
    Du->resize(n_nodes_, 3);
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) (*Du)(static_cast<Eigen::Index>(i), c) = out[9 * i + c], unit_far_[6 * i + c] = out[9 * i + 3 + c],
                                  unit_far_[6 * i + 3 + c] = out[9 * i + 6 + c];
  } else {
    fmm::direct_sum<StressletNormalPair, 1, false>(src_.data(), static_cast<std::size_t>(ns), src_n_.data(), x_.data(), n,
                                                   unit_far_.data(), threads_);
  }
  clock.lap(times_, Phase::BieFar);
  if (verify_now && (refresh || u)) {
    // Full double precision and the r = 0 mask: not the one-Newton pass (or the FMM) it checks.
    // D̃[1], and the first application's far field D̃[u] when it came from the same pass (Du holds
    // only the far field here); the check reports the worse of the two.
    std::vector<double> ref(6 * n);
    FarFieldCheck c;
    c.evaluation = setups_;
    if (refresh) {
      fmm::direct_sum<StressletNormalPair>(src_.data(), static_cast<std::size_t>(ns), src_n_.data(), x_.data(), n, ref.data(),
                                           threads_);
      c = compare_far_field(unit_far_.data(), ref.data(), n, 6, setups_);
    }
    if (u) {
      fmm::direct_sum<fmm::Stresslet>(src_.data(), static_cast<std::size_t>(ns), density_.data(), x_.data(), n, ref.data(),
                                      threads_);
      const FarFieldCheck cu = compare_far_field(Du->data(), ref.data(), n, 3, setups_);
      c.max_relative = std::max(c.max_relative, cu.max_relative), c.rms_relative = std::max(c.rms_relative, cu.rms_relative);
    }
    checks_.add(c, opt_.tolerance);
    clock.lap(times_, Phase::BieVerify);
  }
  if (refresh) {  // the diagonal ½ I − D̃[1]: the far field of the unit constants completes it
#pragma omp parallel for schedule(static) num_threads(threads_)
    for (Eigen::Index i = 0; i < n_nodes_; ++i)
      for (int k = 0; k < 6; ++k) diagonal_[6 * static_cast<size_t>(i) + static_cast<size_t>(k)] -= unit_far_[6 * static_cast<size_t>(i) + static_cast<size_t>(k)];
  }
  if (reuse_) reuse_identity_term(refresh, on_trajectory, sample_called);
  if (u) add_near_field(*u, *Du);
  clock.lap(times_, Phase::BieNear);
  setup_seconds_ += total.seconds();
  ++setups_;
  if (u) ++applications_;
}

void DoubleLayer::assemble_near_field(const Points& x) {
  // Per node i and per kind of listed element (touching: the far rule, subtracted; ring: the
  // 7-point rule minus the far rule; band: the 3-point Gauss rule minus the far rule), the
  // elements go through SIMD lanes, one element per lane: all lanes evaluate T(r)·ñ at the same
  // rule point, whose weights are then the same scalars for every lane, and each element's three
  // vertex blocks are summed in registers and written once.
  using fmm::simd::VecD;
  constexpr int W = VecD::width;
  const auto& far_bary = far_rule_ == FarFieldRule::EdgeMidpoints ? kEdgeMidpointBary : kGaussBary;
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads_)
  for (Eigen::Index visit = 0; visit < n_nodes_; ++visit) {
    const Eigen::Index i = node_order_[static_cast<size_t>(visit)];
    const VecD xi[3] = {VecD(x(i, 0)), VecD(x(i, 1)), VecD(x(i, 2))};
    std::fill(&block_[6 * static_cast<size_t>(block_start_[i])], &block_[6 * static_cast<size_t>(block_start_[i + 1])], 0.0);
    const int* slot = &slot_[static_cast<size_t>(slot_start_[i])];  // 3 blocks per listed element, in list order
    // Elements `list` (their slots from `slots` on): `rule` points (positions y, weighted normals n
    // of `points` per element, barycentrics bary) with sign +1, then the far rule subtracted.
    auto add_elements = [&](IndexRange list, const int* slots, const std::vector<double>* y, const std::vector<double>* n,
                            int points, const double (*bary)[4]) {
      const int count = static_cast<int>(list.size());
      for (int l0 = 0; l0 < count; l0 += W) {
        const int lanes = std::min(W, count - l0);
        VecD acc[3][6];
        for (auto& a : acc)
          for (auto& c : a) c = VecD(0.0);
        alignas(64) double g[6][W];
        // One rule point of every lane's element: gather, evaluate, add with the point's weights.
        auto point = [&](const std::vector<double>& py, const std::vector<double>& pn, int per_element, int p,
                         const double* w, double sign) {
          for (int l = 0; l < W; ++l) {
            const size_t e = static_cast<size_t>(list.first[l0 + std::min(l, lanes - 1)]);
            const double* yp = &py[3 * (static_cast<size_t>(per_element) * e + static_cast<size_t>(p))];
            const double* np = &pn[3 * (static_cast<size_t>(per_element) * e + static_cast<size_t>(p))];
            for (int d = 0; d < 3; ++d) g[d][l] = yp[d], g[3 + d][l] = l < lanes ? np[d] : 0.0;  // padding adds 0
          }
          const VecD r[3] = {xi[0] - VecD::load(g[0]), xi[1] - VecD::load(g[1]), xi[2] - VecD::load(g[2])};
          const VecD nn[3] = {VecD::load(g[3]), VecD::load(g[4]), VecD::load(g[5])};
          VecD m[6] = {VecD(0.0), VecD(0.0), VecD(0.0), VecD(0.0), VecD(0.0), VecD(0.0)};
          StressletNormalPair::eval(m, r, fmm::simd::rsqrt(fmm::simd::fma(r[0], r[0], fmm::simd::fma(r[1], r[1], r[2] * r[2]))), nn);
          for (int k = 0; k < 3; ++k) {
            if (w[k] == 0.0) continue;  // the edge-midpoint rule's third vertex
            const VecD wk(sign * w[k]);
            for (int c = 0; c < 6; ++c) acc[k][c] = fmm::simd::fma(wk, m[c], acc[k][c]);
          }
        };
        if (y)
          for (int p = 0; p < points; ++p) point(*y, *n, points, p, bary[p], 1.0);
        for (int p = 0; p < 3; ++p) point(slot_y_, slot_n_, 3, p, far_bary[p], -1.0);
        alignas(64) double out[3][6][W];
        for (int k = 0; k < 3; ++k)
          for (int c = 0; c < 6; ++c) acc[k][c].store(out[k][c]);
        for (int l = 0; l < lanes; ++l)
          for (int k = 0; k < 3; ++k) {
            double* bk = &block_[6 * static_cast<size_t>(slots[3 * (l0 + l) + k])];
            for (int c = 0; c < 6; ++c) bk[c] += out[k][c][l];
          }
      }
    };
    const IndexRange touching = lists_.touching(i), ring = lists_.ring(i), band = lists_.band(i);
    // A flat touching element contributes nothing, and its far-rule points lie in its plane through
    // x_i, where T(r)·ñ = 0: nothing to subtract either (§4.7.2). A curved one: the far rule
    // subtracted, then its exact singular integral.
    if (surface_.curved()) {
      add_elements(touching, slot, nullptr, nullptr, 0, nullptr);
      for (size_t j = 0; j < touching.size(); ++j) {
        const int e = touching.first[j];
        const int k0 = tri_(e, 0) == i ? 0 : (tri_(e, 1) == i ? 1 : 2);
        const auto Ms = singular_element_double_layer(surface_.element(x, e, k0), rule_, rule_u_);
        for (int k = 0; k < 3; ++k) add(&block_[6 * static_cast<size_t>(slot[3 * j + static_cast<size_t>((k0 + k) % 3)])], 1.0, Ms[static_cast<size_t>(k)]);
      }
    }
    slot += 3 * touching.size();
    add_elements(ring, slot, &ring_y_, &ring_n_, 7, kDunavant7);
    slot += 3 * ring.size();
    // The Gauss rule's barycentrics in rows of four like the 7-point table's (the fourth is unused).
    static constexpr double kGauss4[3][4] = {{kGaussBary[0][0], kGaussBary[0][1], kGaussBary[0][2], 1.0},
                                             {kGaussBary[1][0], kGaussBary[1][1], kGaussBary[1][2], 1.0},
                                             {kGaussBary[2][0], kGaussBary[2][1], kGaussBary[2][2], 1.0}};
    add_elements(band, slot, &band_y_, &band_n_, 3, kGauss4);
    // Scale, then the diagonal ½ I minus the row sums (set_surface subtracts D̃[1]'s far part).
    double* Dg = &diagonal_[6 * static_cast<size_t>(i)];
    for (int k = 0; k < 6; ++k) Dg[k] = k < 3 ? 0.5 : 0.0;
    for (int b = block_start_[i]; b < block_start_[i + 1]; ++b)
      for (int k = 0; k < 6; ++k) {
        block_[6 * static_cast<size_t>(b) + k] *= kInv8Pi;
        Dg[k] -= block_[6 * static_cast<size_t>(b) + k];
      }
  }
}

void DoubleLayer::fill_far_densities(const Points& u) {
  // Per far-field source: u interpolated at its point (f) and its summed weighted normal (n).
  const auto& far_bary = far_rule_ == FarFieldRule::EdgeMidpoints ? kEdgeMidpointBary : kGaussBary;
  const Eigen::Index ns = far_field_sources();
#pragma omp parallel for schedule(static) num_threads(threads_)
  for (Eigen::Index s = 0; s < ns; ++s) {
    const int slot = source_slots_[static_cast<size_t>(s)][0], e = slot / 3;
    const double* l = far_bary[slot % 3];
    double* d = &density_[6 * s];
    for (int k = 0; k < 3; ++k) {
      d[k] = l[0] * u(tri_(e, 0), k) + l[1] * u(tri_(e, 1), k) + l[2] * u(tri_(e, 2), k);
      d[3 + k] = src_n_[3 * s + k];
    }
  }
}

void DoubleLayer::add_near_field(const Points& u, Points& out) const {
#pragma omp parallel for schedule(static) num_threads(threads_)
  for (Eigen::Index i = 0; i < n_nodes_; ++i) {
    Vec3 s = sym_times(&diagonal_[6 * static_cast<size_t>(i)], &u(i, 0));
    for (int b = block_start_[i]; b < block_start_[i + 1]; ++b)
      s += sym_times(&block_[6 * static_cast<size_t>(b)], &u(block_col_[static_cast<size_t>(b)], 0));
    out.row(i) += s.transpose();
  }
}

double DoubleLayer::apply(const Points& u, Points& out, double allowed_error) {
  if (u.rows() != n_nodes_ || x_.rows() != n_nodes_)
    throw std::invalid_argument("double layer: set_surface() first, and one row of u per node");
  Stopwatch clock, total;
  const Eigen::Index ns = far_field_sources();
  fill_far_densities(u);
  clock.lap(times_, Phase::BieSources);
  out.resize(n_nodes_, 3);
  double committed = 0;  // the far field's error bound relative to ‖u‖ (the near field is exact)
  InexactFmm* tier = nullptr;
  for (InexactFmm& t : inexact_fmms_)
    if (allowed_error >= t.allowed_error) {
      tier = &t;
      break;
    }
  if (tier) {
    if (!tier->fmm) tier->fmm = std::make_unique<fmm::Fmm<fmm::Stresslet>>(fmm_options(tier->fmm_tolerance));
    if (!tier->ready) tier->fmm->setup(src_.data(), static_cast<std::size_t>(ns), x_.data(), static_cast<std::size_t>(n_nodes_));
    tier->ready = true;
    tier->fmm->evaluate(density_.data(), out.data());
    ++tier->applications;
    ++inexact_applications_;
    committed = kInexactL2Share * tier->allowed_error;
  } else if (fmm_) {
    if (!fmm_ready_) fmm_->setup(src_.data(), static_cast<std::size_t>(ns), x_.data(), static_cast<std::size_t>(n_nodes_));
    fmm_ready_ = true;
    fmm_->evaluate(density_.data(), out.data());
    committed = kFmmToleranceMargin * opt_.tolerance;  // double_layer_fmm_tolerance's L2 promise
  } else if (fmm::kMixedPrecisionDirectSum && allowed_error >= kMixedPrecisionAllowedError) {
    fmm::direct_sum_mixed<fmm::Stresslet>(src_.data(), static_cast<std::size_t>(ns), density_.data(), x_.data(),
                                          static_cast<std::size_t>(n_nodes_), out.data(), threads_);
    ++inexact_applications_;
    committed = kMixedPrecisionL2Error;
  } else {
    fmm::direct_sum<fmm::Stresslet, 1, false>(src_.data(), static_cast<std::size_t>(ns), density_.data(), x_.data(),
                                              static_cast<std::size_t>(n_nodes_), out.data(), threads_);
  }
  clock.lap(times_, Phase::BieFar);
  add_near_field(u, out);
  clock.lap(times_, Phase::BieNear);
  apply_seconds_ += total.seconds();
  ++applications_;
  return committed;
}

void DoubleLayer::corner_geometry(const Points& x) {
  // Per node C, R and C in the local frame (corner_), and how far the surface moved since the last
  // refresh: the largest change of a node's local corner value (the jump guard).
  const bool since = refresh_records_ > 0;
  double change = 0;
#pragma omp parallel for schedule(static) reduction(max : change) num_threads(threads_)
  for (Eigen::Index i = 0; i < n_nodes_; ++i) {
    const size_t k = static_cast<size_t>(i);
    const Mat3 R = local_frame(x, i), C = corner_double_layer(x, i, *fans_);
    sym_store(C, &corner_[21 * k]);
    Eigen::Map<Mat3> frame(&corner_[21 * k + 6]);
    frame = R;
    const Mat3 local = R.transpose() * C * R;
    sym_store(local, &corner_[21 * k + 15]);
    if (since) change = std::max(change, (local - sym_matrix(&refreshed_[kRecord * k + 6])).norm());
  }
  corner_change_ = change;
  double sampled = 0;
  if (since)
    for (const int i : samples_) {
      const size_t k = static_cast<size_t>(i);
      sampled = std::max(sampled, (sym_matrix(&corner_[21 * k + 15]) - sym_matrix(&refreshed_[kRecord * k + 6])).norm());
    }
  jumped_ = since && change > kCornerJump && change > kCornerOverSampled * sampled;
  sampled_corner_change_ = sampled;
}

bool DoubleLayer::forced_refresh(bool on_trajectory, bool verify_now) const {
  if (refresh_records_ == 0 || jumped_) return true;
  return on_trajectory && verify_now;
}

void DoubleLayer::sample_identity_drift() {
  // D̃[1] summed directly at the sample nodes (far field of the unit constants plus the row sums
  // the assembly left in diagonal_), its error term E in the local frames, and the reuse's value
  // there: E1 + s (E1 − E0) + s2 (E0 − E−1), s and s2 fitted to the sample by least squares (0 after
  // a single refresh).
  const size_t m = samples_.size();
  for (size_t j = 0; j < m; ++j)
    for (int d = 0; d < 3; ++d) sample_x_[3 * j + static_cast<size_t>(d)] = x_(samples_[j], d);
  fmm::direct_sum<StressletNormalPair, 1, false>(src_.data(), src_.size() / 3, src_n_.data(), sample_x_.data(), m,
                                                 sample_far_.data(), threads_);
  std::vector<Mat3>& now = sample_error_;
  // Least squares over the sample of now − E1 ≈ s d1 + s2 d2, d1 = E1 − E0, d2 = E0 − E−1: the
  // normal equations' Gram matrix g and right-hand side r.
  double g11 = 0, g12 = 0, g22 = 0, r1 = 0, r2 = 0;
  for (size_t j = 0; j < m; ++j) {
    const size_t k = static_cast<size_t>(samples_[j]);
    const Mat3 C = sym_matrix(&corner_[21 * k]), R = Eigen::Map<const Mat3>(&corner_[21 * k + 6]);
    const Mat3 D1 = sym_matrix(&sample_far_[6 * j]) + 0.5 * Mat3::Identity() - sym_matrix(&diagonal_[6 * k]);
    now[j] = R.transpose() * (D1 - C) * R;
    if (refresh_records_ < 2) continue;
    const double* record = &refreshed_[kRecord * k];
    const Mat3 E1 = sym_matrix(record), E0 = sym_matrix(record + 12), d1 = E1 - E0;
    g11 += d1.squaredNorm(), r1 += ((now[j] - E1).array() * d1.array()).sum();
    if (refresh_records_ < 3) continue;
    const Mat3 d2 = E0 - sym_matrix(record + 18);
    g12 += (d1.array() * d2.array()).sum(), g22 += d2.squaredNorm(), r2 += ((now[j] - E1).array() * d2.array()).sum();
  }
  // The fit along one secant (s), and after three refreshes along two (s, s2: the quadratic
  // through them); the reuse takes whichever errs less at the sample.
  auto sampled = [&](double a, double b) {
    double d = 0;
    for (size_t j = 0; j < m; ++j)
      d = std::max(d, (now[j] - extrapolated_error(&refreshed_[kRecord * static_cast<size_t>(samples_[j])], a, b)).norm());
    return d;
  };
  extrapolation_ = g11 > 0 ? std::clamp(r1 / g11, kExtrapolationRange[0], kExtrapolationRange[1]) : 0.0;
  extrapolation2_ = 0;
  double drift = sampled(extrapolation_, 0);
  const double det = g11 * g22 - g12 * g12;
  if (refresh_records_ >= 3 && det > kSecantsIndependent * g11 * g22) {
    const double a = std::clamp((r1 * g22 - r2 * g12) / det, kQuadraticRange[0], kQuadraticRange[1]);
    const double b = std::clamp((g11 * r2 - g12 * r1) / det, kQuadraticRange[0], kQuadraticRange[1]);
    const double quadratic = sampled(a, b);
    if (quadratic < drift) extrapolation_ = a, extrapolation2_ = b, drift = quadratic;
  }
  sampled_drift_ = drift;
}

Mat3 DoubleLayer::local_frame(const Points& x, Eigen::Index i) const {
  // Columns: tangent (towards the fan's first p), binormal, normal (area-weighted, outward).
  const Vec3 xi = x.row(i).transpose();
  Vec3 n = Vec3::Zero();
  for (int f = fans_->start[static_cast<size_t>(i)]; f < fans_->start[static_cast<size_t>(i) + 1]; ++f) {
    const CornerFacet& F = fans_->facets[static_cast<size_t>(f)];
    n += (x.row(F.p).transpose() - xi).cross(x.row(F.q).transpose() - xi);
  }
  n.normalize();
  const Vec3 p = x.row(fans_->facets[static_cast<size_t>(fans_->start[static_cast<size_t>(i)])].p).transpose() - xi;
  const Vec3 t = (p - p.dot(n) * n).normalized();
  Mat3 R;
  R.col(0) = t, R.col(1) = n.cross(t), R.col(2) = n;
  return R;
}

void DoubleLayer::reuse_identity_term(bool refreshed, bool on_trajectory, bool sample_called) {
  // diagonal_ holds ½ I − D̃[1] from the pass on a refresh; otherwise ½ I − (C + R E Rᵀ) is imposed,
  // E = E1 + s (E1 − E0) + s2 (E0 − E−1) (sample_identity_drift). refreshed_ per node, in the local
  // frames of their refreshes: E1, C1 (the last refresh), E0 and E−1 (the two before).
  // An off-trajectory set-up that had to take the full pass (its surface jumped from the
  // reference) uses it for itself only: storing its E would make the run depend on its outputs.
  if (refreshed && !on_trajectory) return;
  // After a jump the older refresh lies on another surface: the line starts again from this one.
  const bool restart_line = refreshed && jumped_;
  // A refresh the sample called measures, over all nodes, the drift of the reuse it replaced: how
  // far the sample's estimate falls short of the whole surface's. Forced refreshes (the first, a
  // corner jump, a verified surface) replace no reuse that the sample passed.
  const bool measure = sample_called && refresh_records_ > 0;
  const double s = extrapolation_, s2 = extrapolation2_;
  double drift = 0;
#pragma omp parallel for schedule(static) reduction(max : drift) num_threads(threads_)
  for (Eigen::Index i = 0; i < n_nodes_; ++i) {
    const size_t k = static_cast<size_t>(i);
    const Mat3 C = sym_matrix(&corner_[21 * k]), R = Eigen::Map<const Mat3>(&corner_[21 * k + 6]);
    double* Dg = &diagonal_[6 * k];
    double* record = &refreshed_[kRecord * k];
    if (refreshed) {
      const Mat3 D1 = 0.5 * Mat3::Identity() - sym_matrix(Dg);
      if (measure) drift = std::max(drift, (D1 - C - R * extrapolated_error(record, s, s2) * R.transpose()).norm());
      std::copy(record + 12, record + 18, record + 18);
      std::copy(record, record + 6, record + 12);
      sym_store(R.transpose() * (D1 - C) * R, record);
      std::copy(&corner_[21 * k + 15], &corner_[21 * k + 21], record + 6);
    } else {
      sym_store(0.5 * Mat3::Identity() - (C + R * extrapolated_error(record, s, s2) * R.transpose()), Dg);
    }
  }
  if (!refreshed) return;
  if (measure) {
    max_drift_ = std::max(max_drift_, drift);
    max_drift_over_sampled_ = std::max(max_drift_over_sampled_, drift / sampled_drift_);  // sampled_drift_ > 0 here
  }
  refresh_records_ = restart_line ? 1 : std::min(refresh_records_ + 1, 3);
  ++refreshes_;
}

Mat3 DoubleLayer::unit_constant_integral(Eigen::Index i) const {
  return 0.5 * Mat3::Identity() - sym_matrix(&diagonal_[6 * static_cast<size_t>(i)]);
}

}  // namespace capsflow
