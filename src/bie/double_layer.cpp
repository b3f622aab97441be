#include "capsflow/core/bie/double_layer.hpp"

#include <algorithm>
#include <iterator>
#include <stdexcept>

#include "capsflow/core/bie/stresslet_pair.hpp"
#include "capsflow/fmm/calibration.hpp"
#include "capsflow/fmm/direct_sum_mixed.hpp"
#include "capsflow/fmm/simd.hpp"
#include "capsflow/fmm/stresslet.hpp"

namespace capsflow {

namespace {
using fmm::simd::VecD;
constexpr int W = VecD::width;
constexpr double kInv8Pi = fmm::Stresslet::scale();
constexpr int kMainFmm = FarField<fmm::Stresslet>::kMainFmm;
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
// The Gauss rule's barycentrics in rows of four like the 7-point table's (the fourth is unused).
constexpr double kGauss4[3][4] = {{kGaussBary[0][0], kGaussBary[0][1], kGaussBary[0][2], 1.0},
                                  {kGaussBary[1][0], kGaussBary[1][1], kGaussBary[1][2], 1.0},
                                  {kGaussBary[2][0], kGaussBary[2][1], kGaussBary[2][2], 1.0}};

inline void add(double* b, double c, const Mat3& m) {
  b[0] += c * m(0, 0), b[1] += c * m(1, 1), b[2] += c * m(2, 2);
  b[3] += c * m(0, 1), b[4] += c * m(0, 2), b[5] += c * m(1, 2);
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
// One rule point p (of per_element per element: positions py, weighted normals pn) of the elements
// in `lanes` SIMD lanes (the last one repeated in the padding lanes, whose normals are 0 so that
// they add exactly 0): gathered, T(r)·ñ evaluated at x_i, added with the point's weights w (one
// per vertex) and `sign` to each lane's three vertex blocks.
inline void add_rule_point(const VecD (&xi)[3], const int* elements, int lanes, const std::vector<double>& py,
                           const std::vector<double>& pn, int per_element, int p, const double* w, double sign,
                           VecD (&acc)[3][6]) {
  alignas(64) double g[6][W];
  for (int l = 0; l < W; ++l) {
    const size_t e = static_cast<size_t>(elements[std::min(l, lanes - 1)]);
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
}
}  // namespace

DoubleLayer::DoubleLayer(const Triangles& triangles, Eigen::Index n_nodes, const DoubleLayerOptions& opt)
    : tri_(triangles),
      n_nodes_(n_nodes),
      opt_(opt),
      threads_(layer_threads(opt)),
      rule_(opt.singular_points),
      rule_u_(opt.singular_radial_points),
      lists_(triangles, n_nodes, near_ring_layers(opt), corrected_layers(opt, near_ring_layers(opt), kAutoDoubleLayerCorrectedLayers)),
      surface_(triangles, opt.geometry),
      far_(lists_, triangles.rows(), n_nodes, opt, threads_) {
  if (far_.backend() == FarFieldBackend::Fmm && opt.fmm_order <= 0) build_inexact_ladder();
  const size_t m = static_cast<size_t>(tri_.rows());
  if (lists_.corrected_layers() > lists_.ring_layers()) band_y_.resize(9 * m), band_n_.resize(9 * m);
  if (lists_.ring_layers() > 0) ring_y_.resize(21 * m), ring_n_.resize(21 * m);
  density_.resize(6 * static_cast<size_t>(far_.sources()));
  build_near_pattern();
  // The corner value is the flat polyhedron's: curved elements take the full pass on every set-up.
  // So does the direct back end: its pair loop costs the pair geometry for one density as for four
  // (measured at 5 120 elements: no gain); the FMM's cost follows the densities.
  if (surface_.curved() || !opt.reuse_identity_term || far_.backend() != FarFieldBackend::Fmm) return;
  identity_ = std::make_unique<IdentityTermCache>(triangles, n_nodes, node_order_, opt.tolerance, threads_);
  const size_t samples = identity_->samples().size();
  sample_x_.resize(3 * samples), sample_far_.resize(6 * samples), sample_exact_.resize(samples);
  // The refresh pass at the order whose error (relative to the density, in max: the allowance's
  // norm) is a quarter of the allowance: its E is what the set-ups between reuse and extrapolate.
  const double refresh_max = identity_->refresh_pass_error();
  const double tolerance = double_layer_fmm_tolerance(refresh_max, refresh_max);
  if (opt.fmm_order <= 0 && tolerance < double_layer_fmm_tolerance(opt.tolerance)) refresh_fmm_ = far_.add_fmm(tolerance);
}

DoubleLayer::~DoubleLayer() = default;
DoubleLayer::DoubleLayer(DoubleLayer&&) noexcept = default;

void DoubleLayer::build_inexact_ladder() {
  // From the strictest allowance on, each tier only where its order is lower than the next
  // stricter one's (no cheaper order to gain otherwise).
  int stricter_order = far_.fmm_order();
  for (size_t k = std::size(kInexactFmmAllowedErrors); k-- > 0;) {
    const double allowed = kInexactFmmAllowedErrors[k];
    const double tolerance = double_layer_fmm_tolerance(kInexactL2Share * allowed, allowed);
    const int order = fmm::order_for_tolerance<fmm::Stresslet>(tolerance);
    if (order >= stricter_order) continue;
    stricter_order = order;
    inexact_fmms_.insert(inexact_fmms_.begin(), InexactFmm{allowed, tolerance, order});
  }
}

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
  visit_breadth_first();
}

void DoubleLayer::visit_breadth_first() {
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
  far_.set_targets(x.data(), n_nodes_);  // every FMM is set up again on its first use on this surface
  place_points(x);
  clock.lap(times_, Phase::BieSources);
  // The near blocks and their row sums first (diagonal_ = ½ I − the row sums): the sampled drift
  // needs them, and they do not depend on the far field.
  assemble_near_field(x);
  clock.lap(times_, Phase::BieNear);
  unit_far_.resize(6 * static_cast<size_t>(n_nodes_));
  if (u) fill_far_densities(*u);
  // A surface whose far field is verified takes the FMM pass even where the set-up sums directly:
  // the check is of the FMM (set-up, operators, order) that every iteration on it uses.
  const bool verify_now = far_.check_due(setups_);
  bool sample_called = false;
  const bool refresh = identity_refresh(x, on_trajectory, verify_now, sample_called);
  if (identity_) clock.lap(times_, Phase::BieSources);
  set_up_far_field(refresh, verify_now, u, Du);
  clock.lap(times_, Phase::BieFar);
  if (verify_now && (refresh || u)) {
    check_set_up(refresh, u, Du);
    clock.lap(times_, Phase::BieVerify);
  }
  complete_diagonal(refresh, on_trajectory, sample_called);
  if (u) add_near_field(*u, *Du);
  clock.lap(times_, Phase::BieNear);
  setup_seconds_ += total.seconds();
  ++setups_;
  if (u) ++applications_;
}

void DoubleLayer::place_points(const Points& x) {
  // The far field's points and weighted normals, and each element's own near-field rules: the
  // band's 3-point rule and Dunavant's 7 points of the ring.
  surface_.update(x, threads_);
  auto far_point = [](const QuadraticTriangle& T, Eigen::Index, const double* l, double w, double* y, double* n) {
    rule_point(T, l, w, y, n);
  };
  auto near_rules = [&](const QuadraticTriangle& T, Eigen::Index e) {
    const size_t k = static_cast<size_t>(e);
    if (!band_y_.empty())
      for (size_t g = 0; g < 3; ++g) rule_point(T, kGaussBary[g], 1.0 / 6.0, &band_y_[9 * k + 3 * g], &band_n_[9 * k + 3 * g]);
    if (!ring_y_.empty())
      for (size_t p = 0; p < 7; ++p)
        rule_point(T, kDunavant7[p], 0.5 * kDunavant7[p][3], &ring_y_[21 * k + 3 * p], &ring_n_[21 * k + 3 * p]);
  };
  far_.place(x, surface_, far_point, near_rules);
}

void DoubleLayer::assemble_near_field(const Points& x) {
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads_)
  for (Eigen::Index visit = 0; visit < n_nodes_; ++visit) assemble_row(node_order_[static_cast<size_t>(visit)], x);
}

void DoubleLayer::assemble_row(Eigen::Index i, const Points& x) {
  // Node i's blocks, per kind of listed element: touching (the far rule, subtracted), ring (the
  // 7-point rule minus the far rule), band (the 3-point Gauss rule minus the far rule).
  std::fill(&block_[6 * static_cast<size_t>(block_start_[i])], &block_[6 * static_cast<size_t>(block_start_[i + 1])], 0.0);
  const int* slot = &slot_[static_cast<size_t>(slot_start_[i])];  // 3 blocks per listed element, in list order
  const IndexRange touching = lists_.touching(i), ring = lists_.ring(i), band = lists_.band(i);
  // A flat touching element contributes nothing, and its far-rule points lie in its plane through
  // x_i, where T(r)·ñ = 0: nothing to subtract either (§4.7.2). A curved one: the far rule
  // subtracted, then its exact singular integral.
  if (surface_.curved()) {
    add_elements(i, x, touching, slot, nullptr, nullptr, 0, nullptr);
    for (size_t j = 0; j < touching.size(); ++j) {
      const int e = touching.first[j];
      const int k0 = tri_(e, 0) == i ? 0 : (tri_(e, 1) == i ? 1 : 2);
      const auto Ms = singular_element_double_layer(surface_.element(x, e, k0), rule_, rule_u_);
      for (int k = 0; k < 3; ++k) add(&block_[6 * static_cast<size_t>(slot[3 * j + static_cast<size_t>((k0 + k) % 3)])], 1.0, Ms[static_cast<size_t>(k)]);
    }
  }
  slot += 3 * touching.size();
  add_elements(i, x, ring, slot, &ring_y_, &ring_n_, 7, kDunavant7);
  slot += 3 * ring.size();
  add_elements(i, x, band, slot, &band_y_, &band_n_, 3, kGauss4);
  // Scale, then the diagonal ½ I minus the row sums (set_surface subtracts D̃[1]'s far part).
  double* Dg = &diagonal_[6 * static_cast<size_t>(i)];
  for (int k = 0; k < 6; ++k) Dg[k] = k < 3 ? 0.5 : 0.0;
  for (int b = block_start_[i]; b < block_start_[i + 1]; ++b)
    for (int k = 0; k < 6; ++k) {
      block_[6 * static_cast<size_t>(b) + k] *= kInv8Pi;
      Dg[k] -= block_[6 * static_cast<size_t>(b) + k];
    }
}

void DoubleLayer::add_elements(Eigen::Index i, const Points& x, IndexRange list, const int* slots, const std::vector<double>* y,
                               const std::vector<double>* n, int points, const double (*bary)[4]) {
  // The elements `list` (their blocks' slots from `slots` on) go through SIMD lanes, one element per
  // lane: all lanes evaluate T(r)·ñ at the same rule point, whose weights are then the same scalars
  // for every lane, and each element's three vertex blocks are summed in registers and written
  // once. The rule (`points` per element: positions y, weighted normals n, barycentrics bary) with
  // sign +1, then the far rule subtracted.
  const VecD xi[3] = {VecD(x(i, 0)), VecD(x(i, 1)), VecD(x(i, 2))};
  const int count = static_cast<int>(list.size());
  for (int l0 = 0; l0 < count; l0 += W) {
    const int lanes = std::min(W, count - l0);
    VecD acc[3][6];
    for (auto& a : acc)
      for (auto& c : a) c = VecD(0.0);
    if (y)
      for (int p = 0; p < points; ++p) add_rule_point(xi, list.first + l0, lanes, *y, *n, points, p, bary[p], 1.0, acc);
    for (int p = 0; p < 3; ++p)
      add_rule_point(xi, list.first + l0, lanes, far_.slot_positions(), far_.slot_values(), 3, p, far_.rule_point(p), -1.0, acc);
    alignas(64) double out[3][6][W];
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 6; ++c) acc[k][c].store(out[k][c]);
    for (int l = 0; l < lanes; ++l)
      for (int k = 0; k < 3; ++k) {
        double* bk = &block_[6 * static_cast<size_t>(slots[3 * (l0 + l) + k])];
        for (int c = 0; c < 6; ++c) bk[c] += out[k][c][l];
      }
  }
}

bool DoubleLayer::identity_refresh(const Points& x, bool on_trajectory, bool verify_now, bool& sample_called) {
  // Whether this set-up takes D̃[1] from the full far-field pass: always without the reuse; with it,
  // when the cache must refresh (forced) or the sample's drift calls for it.
  sample_called = false;
  if (!identity_) return true;
  identity_->set_surface(x);
  if (identity_->forced_refresh(on_trajectory, verify_now)) return true;
  sample_identity_term();
  sample_called = identity_->measure(sample_exact_, on_trajectory);
  return sample_called;
}

void DoubleLayer::sample_identity_term() {
  // D̃[1] summed directly at the sample nodes: the far field of the unit constants plus the row
  // sums the assembly left in diagonal_.
  const std::vector<int>& samples = identity_->samples();
  const size_t m = samples.size();
  for (size_t j = 0; j < m; ++j)
    for (size_t d = 0; d < 3; ++d) sample_x_[3 * j + d] = far_.targets()[3 * static_cast<size_t>(samples[j]) + d];
  far_.direct<StressletNormalPair>(far_.values(), sample_x_.data(), m, sample_far_.data(), DirectPairs::Fast);
  for (size_t j = 0; j < m; ++j)
    sample_exact_[j] = symmetric_matrix(&sample_far_[6 * j]) + 0.5 * Mat3::Identity() -
                       symmetric_matrix(&diagonal_[6 * static_cast<size_t>(samples[j])]);
}

void DoubleLayer::set_up_far_field(bool refresh, bool verify_now, const Points* u, Points* Du) {
  // D̃[1]'s far part: the far field of the unit constants (one pass of T(r)·ñ) — or, between
  // refreshes, nothing: C plus the reused error term replace it. Given u, its far field D̃[u]
  // comes from the same pass (the pair geometry computed once).
  if (refresh && far_.backend() == FarFieldBackend::Fmm && (!far_.set_up_directly() || verify_now)) {
    set_up_far_field_fmm(verify_now, u, Du);
  } else if (refresh) {
    set_up_far_field_direct(u, Du);
  } else if (u) {  // the reuse implies the FMM back end: the first application's pass alone
    Du->resize(n_nodes_, 3);
    far_.evaluate(kMainFmm, density_.data(), Du->data());
  }
}

void DoubleLayer::set_up_far_field_fmm(bool verify_now, const Points* u, Points* Du) {
  // The FMM of the three unit constants (f = e_k, n = ñ), and of u, in one call, at the refresh
  // pass's order; T_ijk ñ_k is symmetric in i, j. A verified surface sums u by the iterations'
  // FMM instead, which the check is of.
  const int F = refresh_fmm_ >= 0 ? refresh_fmm_ : kMainFmm;
  const bool u_here = u && !(verify_now && refresh_fmm_ >= 0);
  const size_t n = static_cast<size_t>(n_nodes_), ns = static_cast<size_t>(far_.sources());
  const int sets = u_here ? 4 : 3;
  std::vector<double> dens(6 * static_cast<size_t>(sets) * ns), out(3 * static_cast<size_t>(sets) * n);
  const double* normals = far_.values();
  for (size_t s = 0; s < ns; ++s)
    for (size_t k = 0; k < 3; ++k) {
      double* d = &dens[6 * (k * ns + s)];
      for (size_t c = 0; c < 3; ++c) d[c] = c == k ? 1.0 : 0.0, d[3 + c] = normals[3 * s + c];
    }
  if (u_here) std::copy(density_.begin(), density_.end(), dens.begin() + 18 * static_cast<std::ptrdiff_t>(ns));
  far_.evaluate(F, dens.data(), out.data(), sets);
  for (size_t i = 0; i < n; ++i) {
    auto col = [&](size_t k, size_t c) { return out[3 * (k * n + i) + c]; };  // D̃[e_k]_c
    double* f = &unit_far_[6 * i];
    f[0] = col(0, 0), f[1] = col(1, 1), f[2] = col(2, 2);
    f[3] = 0.5 * (col(1, 0) + col(0, 1)), f[4] = 0.5 * (col(2, 0) + col(0, 2)), f[5] = 0.5 * (col(2, 1) + col(1, 2));
  }
  if (u) Du->resize(n_nodes_, 3);
  if (u_here)
    std::copy(out.begin() + 9 * static_cast<std::ptrdiff_t>(n), out.end(), Du->data());
  else if (u)
    far_.evaluate(kMainFmm, density_.data(), Du->data());
}

void DoubleLayer::set_up_far_field_direct(const Points* u, Points* Du) {
  // Far-field points are interior to elements or edge midpoints, never a node: the fast pairs.
  const size_t n = static_cast<size_t>(n_nodes_);
  if (!u) {
    far_.direct<StressletNormalPair>(far_.values(), unit_far_.data(), DirectPairs::Fast);
    return;
  }
  std::vector<double> out(9 * n);
  far_.direct<StressletAndNormalPair>(density_.data(), out.data(), DirectPairs::Fast);
  Du->resize(n_nodes_, 3);
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < 3; ++c)
      (*Du)(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)) = out[9 * i + c], unit_far_[6 * i + c] = out[9 * i + 3 + c],
                                  unit_far_[6 * i + 3 + c] = out[9 * i + 6 + c];
}

void DoubleLayer::check_set_up(bool refresh, const Points* u, const Points* Du) {
  // Full double precision and the r = 0 mask: not the one-Newton pass (or the FMM) it checks.
  // D̃[1], and the first application's far field D̃[u] when it came from the same pass (Du holds
  // only the far field here); the check reports the worse of the two.
  FarFieldCheck c;
  c.evaluation = setups_;
  if (refresh) c = far_.compare_with_direct<StressletNormalPair>(far_.values(), unit_far_.data(), setups_);
  if (u) {
    const FarFieldCheck cu = far_.compare_with_direct(density_.data(), Du->data(), setups_);
    c.max_relative = std::max(c.max_relative, cu.max_relative), c.rms_relative = std::max(c.rms_relative, cu.rms_relative);
  }
  far_.record(c);
}

void DoubleLayer::complete_diagonal(bool refresh, bool on_trajectory, bool sample_called) {
  if (!refresh) {  // ½ I − (C + the reused error term)
    identity_->reuse(diagonal_.data());
    return;
  }
  // The diagonal ½ I − D̃[1]: the far field of the unit constants completes it.
#pragma omp parallel for schedule(static) num_threads(threads_)
  for (Eigen::Index i = 0; i < n_nodes_; ++i)
    for (int k = 0; k < 6; ++k) diagonal_[6 * static_cast<size_t>(i) + static_cast<size_t>(k)] -= unit_far_[6 * static_cast<size_t>(i) + static_cast<size_t>(k)];
  if (identity_) identity_->refresh(diagonal_.data(), on_trajectory, sample_called);
}

void DoubleLayer::fill_far_densities(const Points& u) {
  // Per far-field source: u interpolated at its point (f) and its summed weighted normal (n).
  const Eigen::Index ns = far_.sources();
  const double* normals = far_.values();
#pragma omp parallel for schedule(static) num_threads(threads_)
  for (Eigen::Index s = 0; s < ns; ++s) {
    const int slot = far_.slots(s)[0], e = slot / 3;
    const double* l = far_.rule_point(slot % 3);
    double* d = &density_[6 * s];
    for (int k = 0; k < 3; ++k) {
      d[k] = l[0] * u(tri_(e, 0), k) + l[1] * u(tri_(e, 1), k) + l[2] * u(tri_(e, 2), k);
      d[3 + k] = normals[3 * s + k];
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
  if (u.rows() != n_nodes_ || far_.n_targets() != n_nodes_)
    throw std::invalid_argument("double layer: set_surface() first, and one row of u per node");
  Stopwatch clock, total;
  fill_far_densities(u);
  clock.lap(times_, Phase::BieSources);
  out.resize(n_nodes_, 3);
  const double committed = apply_far_field(out, allowed_error);
  clock.lap(times_, Phase::BieFar);
  add_near_field(u, out);
  clock.lap(times_, Phase::BieNear);
  apply_seconds_ += total.seconds();
  ++applications_;
  return committed;
}

double DoubleLayer::apply_far_field(Points& out, double allowed_error) {
  // The error bound relative to ‖u‖ is the far field's: the near field is exact.
  InexactFmm* tier = nullptr;
  for (InexactFmm& t : inexact_fmms_)
    if (allowed_error >= t.allowed_error) {
      tier = &t;
      break;
    }
  if (tier) {
    if (tier->fmm < 0) tier->fmm = far_.add_fmm(tier->fmm_tolerance);
    far_.evaluate(tier->fmm, density_.data(), out.data());
    ++tier->applications;
    ++inexact_applications_;
    return kInexactL2Share * tier->allowed_error;
  }
  if (far_.backend() == FarFieldBackend::Fmm) {
    far_.evaluate(kMainFmm, density_.data(), out.data());
    return kFmmToleranceMargin * opt_.tolerance;  // double_layer_fmm_tolerance's L2 promise
  }
  if (fmm::kMixedPrecisionDirectSum && allowed_error >= kMixedPrecisionAllowedError) {
    far_.direct(density_.data(), out.data(), DirectPairs::Single);
    ++inexact_applications_;
    return kMixedPrecisionL2Error;
  }
  far_.direct(density_.data(), out.data(), DirectPairs::Fast);
  return 0;
}

const std::vector<double>& DoubleLayer::identity_records() const {
  static const std::vector<double> none;
  return identity_ ? identity_->records() : none;
}

bool DoubleLayer::set_identity_records(const std::vector<double>& records, int count) {
  if (!identity_) return records.empty();
  return identity_->set_records(records, count);
}

Mat3 DoubleLayer::unit_constant_integral(Eigen::Index i) const {
  return 0.5 * Mat3::Identity() - symmetric_matrix(&diagonal_[6 * static_cast<size_t>(i)]);
}

DoubleLayerDiagnostics DoubleLayer::diagnostics() const {
  DoubleLayerDiagnostics d;
  d.backend = far_.backend();
  d.backend_reason = far_.reason();
  d.far_field_sources = far_.sources();
  d.fmm_order = far_.fmm_order();
  d.refresh_fmm_order = far_.fmm_order(refresh_fmm_ >= 0 ? refresh_fmm_ : kMainFmm);
  for (const InexactFmm& t : inexact_fmms_) {
    d.inexact_fmm_uses.push_back({t.allowed_error, t.order, t.applications});
    if (t.allowed_error <= std::end(kInexactFmmAllowedErrors)[-1]) d.inexact_fmm_order = t.order;
  }
  d.blocks_per_node = static_cast<double>(block_col_.size()) / static_cast<double>(n_nodes_);
  d.near_field_megabytes = (8.0 * static_cast<double>(block_.size() + diagonal_.size()) +
                            4.0 * static_cast<double>(block_col_.size() + slot_.size() + block_start_.size() + slot_start_.size())) /
                           1e6;
  d.setups = setups_, d.applications = applications_, d.inexact_applications = inexact_applications_;
  d.setup_seconds = setup_seconds_, d.apply_seconds = apply_seconds_;
  d.reuses_identity_term = identity_ != nullptr;
  if (identity_) d.identity = identity_->stats();
  return d;
}

}  // namespace capsflow
