#include "capsflow/core/bie/double_layer.hpp"

#include <omp.h>

#include <algorithm>
#include <stdexcept>

#include "capsflow/core/bie/stresslet_pair.hpp"
#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/fmm.hpp"
#include "capsflow/fmm/stresslet.hpp"

namespace capsflow {

namespace {
constexpr double kInv8Pi = fmm::Stresslet::scale();
// As the single layer: the FMM calibration is a relative L2 error, the tolerance a max norm.
constexpr double kFmmToleranceMargin = 0.25;

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
}  // namespace

DoubleLayer::DoubleLayer(const Triangles& triangles, Eigen::Index n_nodes, const SingleLayerOptions& opt)
    : tri_(triangles),
      n_nodes_(n_nodes),
      opt_(opt),
      threads_(opt.threads > 0 ? opt.threads : omp_get_max_threads()),
      far_rule_(far_field_rule(opt)),
      rule_(opt.singular_points),
      rule_u_(opt.singular_radial_points),
      lists_(triangles, n_nodes, near_ring_layers(opt), corrected_layers(opt)),
      surface_(triangles, opt.geometry),
      source_slots_(far_field_source_slots(lists_, triangles.rows(), far_rule_ == FarFieldRule::EdgeMidpoints)) {
  if (opt.near_ring_depth > 0) throw std::invalid_argument("double layer: near_ring_depth > 0 is not supported");
  backend_ = choose_backend(opt.backend, far_field_sources(), n_nodes, opt.tolerance, &reason_);
  if (backend_ == FarFieldBackend::Fmm) {
    fmm::FmmOptions fo;
    fo.tolerance = kFmmToleranceMargin * opt.tolerance;
    fo.order = opt.fmm_order;
    fo.threads = threads_;
    fmm_ = std::make_unique<fmm::Fmm<fmm::Stresslet>>(fo);
  }
  const size_t m = static_cast<size_t>(tri_.rows()), ns = source_slots_.size();
  slot_y_.resize(9 * m), slot_n_.resize(9 * m);
  if (lists_.corrected_layers() > lists_.ring_layers()) band_y_.resize(9 * m), band_n_.resize(9 * m);
  if (lists_.ring_layers() > 0) ring_y_.resize(21 * m), ring_n_.resize(21 * m);
  src_.resize(3 * ns), src_n_.resize(3 * ns), density_.resize(6 * ns);
  build_near_pattern();
}

DoubleLayer::~DoubleLayer() = default;
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
    max_points_per_node_ = std::max(max_points_per_node_, 3 * static_cast<int>(lists_.touching(i).size()) +
                                                              10 * static_cast<int>(lists_.ring(i).size()) +
                                                              6 * static_cast<int>(lists_.band(i).size()));
  }
  block_.resize(6 * block_col_.size());
  diagonal_.resize(static_cast<size_t>(6 * n_nodes_));
}

void DoubleLayer::set_surface(const Points& x, const Points* u, Points* Du) {
  if (x.rows() != n_nodes_) throw std::invalid_argument("double layer: positions must have one row per node");
  if ((u == nullptr) != (Du == nullptr) || (u && u->rows() != n_nodes_))
    throw std::invalid_argument("double layer: set_surface's first application needs u (one row per node) and Du");
  Stopwatch clock, total;
  x_ = x;
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
  // D̃[1]: the far field of the unit constants (one pass of T(r)·ñ), then the near blocks' row sums.
  // Given u, its far field D̃[u] comes from the same pass (the pair geometry computed once).
  // Far-field points are interior to elements or edge midpoints, never a node: no r = 0 test, one
  // Newton step (≤ 6e-9 per pair), as for the single layer's direct far field.
  const size_t n = static_cast<size_t>(n_nodes_);
  unit_far_.resize(6 * n);
  if (u) fill_far_densities(*u);
  if (fmm_) {
    // The FMM of the three unit constants (f = e_k, n = ñ), and of u, in one call; T_ijk ñ_k is
    // symmetric in i, j.
    fmm_->setup(src_.data(), static_cast<std::size_t>(ns), x_.data(), n);
    const int sets = u ? 4 : 3;
    std::vector<double> dens(6 * static_cast<size_t>(sets * ns)), out(3 * static_cast<size_t>(sets) * n);
    for (Eigen::Index s = 0; s < ns; ++s)
      for (int k = 0; k < 3; ++k) {
        double* d = &dens[6 * (static_cast<size_t>(k * ns + s))];
        for (int c = 0; c < 3; ++c) d[c] = c == k ? 1.0 : 0.0, d[3 + c] = src_n_[3 * s + c];
      }
    if (u) std::copy(density_.begin(), density_.end(), dens.begin() + 18 * static_cast<std::ptrdiff_t>(ns));
    fmm_->evaluate(dens.data(), out.data(), sets);
    for (size_t i = 0; i < n; ++i) {
      auto col = [&](int k, int c) { return out[3 * (k * n + i) + static_cast<size_t>(c)]; };  // D̃[e_k]_c
      double* f = &unit_far_[6 * i];
      f[0] = col(0, 0), f[1] = col(1, 1), f[2] = col(2, 2);
      f[3] = 0.5 * (col(1, 0) + col(0, 1)), f[4] = 0.5 * (col(2, 0) + col(0, 2)), f[5] = 0.5 * (col(2, 1) + col(1, 2));
    }
    if (u) {
      Du->resize(n_nodes_, 3);
      std::copy(out.begin() + 9 * static_cast<std::ptrdiff_t>(n), out.end(), Du->data());
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
  assemble_near_field(x);
  if (u) add_near_field(*u, *Du);
  clock.lap(times_, Phase::BieNear);
  setup_seconds_ += total.seconds();
  ++setups_;
  if (u) ++applications_;
}

void DoubleLayer::assemble_near_field(const Points& x) {
  // Per node: gather the rule points of its listed elements (touching: the far rule, subtracted;
  // ring: 7-point rule minus the far rule; band: 3-point Gauss rule minus the far rule), evaluate
  // T(r)·ñ for all of them in SIMD lanes, then add each element's points to its three vertex
  // blocks, summed per element first so that a block is written once per element.
  using fmm::simd::VecD;
  constexpr int W = VecD::width;
  const auto& far_bary = far_rule_ == FarFieldRule::EdgeMidpoints ? kEdgeMidpointBary : kGaussBary;
  const size_t cap = static_cast<size_t>((max_points_per_node_ + W - 1) / W * W);
#pragma omp parallel num_threads(threads_)
  {
    // Per point: y (3) and ñ (3) in structure of arrays for the SIMD lanes; T·ñ (6, padded to 8)
    // per point for the per-element sums, whose 8 components then add as one vector.
    std::vector<double> pts(6 * cap), mat(8 * cap, 0.0);
    double* const py[6] = {&pts[0], &pts[cap], &pts[2 * cap], &pts[3 * cap], &pts[4 * cap], &pts[5 * cap]};
    double* const pm = mat.data();
#pragma omp for schedule(dynamic, 64)
    for (Eigen::Index i = 0; i < n_nodes_; ++i) {
      const double xi[3] = {x(i, 0), x(i, 1), x(i, 2)};
      int K = 0;
      auto gather = [&](const std::vector<double>& y, const std::vector<double>& n, int e, int points) {
        for (int p = 0; p < points; ++p, ++K)
          for (int d = 0; d < 3; ++d)
            py[d][K] = y[3 * static_cast<size_t>(points * e + p) + d], py[3 + d][K] = n[3 * static_cast<size_t>(points * e + p) + d];
      };
      for (int e : lists_.touching(i)) gather(slot_y_, slot_n_, e, 3);
      for (int e : lists_.ring(i)) gather(ring_y_, ring_n_, e, 7), gather(slot_y_, slot_n_, e, 3);
      for (int e : lists_.band(i)) gather(band_y_, band_n_, e, 3), gather(slot_y_, slot_n_, e, 3);
      for (int q = K; q < (K + W - 1) / W * W; ++q)  // padding lanes: away from x_i, ñ = 0 (adds 0)
        for (int d = 0; d < 3; ++d) py[d][q] = xi[d] + (d == 0 ? 1.0 : 0.0), py[3 + d][q] = 0.0;
      for (int q = 0; q < K; q += W) {
        const VecD r[3] = {VecD(xi[0]) - VecD::load(py[0] + q), VecD(xi[1]) - VecD::load(py[1] + q),
                           VecD(xi[2]) - VecD::load(py[2] + q)};
        const VecD n[3] = {VecD::load(py[3] + q), VecD::load(py[4] + q), VecD::load(py[5] + q)};
        VecD m[6] = {VecD(0.0), VecD(0.0), VecD(0.0), VecD(0.0), VecD(0.0), VecD(0.0)};
        StressletNormalPair::eval(m, r, fmm::simd::rsqrt(fmm::simd::fma(r[0], r[0], fmm::simd::fma(r[1], r[1], r[2] * r[2]))), n);
        alignas(64) double lanes[6][W];
        for (int c = 0; c < 6; ++c) m[c].store(lanes[c]);
        for (int l = 0; l < W; ++l)
          for (int c = 0; c < 6; ++c) pm[8 * static_cast<size_t>(q + l) + static_cast<size_t>(c)] = lanes[c][l];
      }
      std::fill(&block_[6 * static_cast<size_t>(block_start_[i])], &block_[6 * static_cast<size_t>(block_start_[i + 1])], 0.0);
      const int* slot = &slot_[static_cast<size_t>(slot_start_[i])];
      int q = 0;
      alignas(64) double acc[3][8];
      // Adds `points` consecutive points with weights sign·bary(p)[k] to the element's accumulators.
      auto add_points = [&](int points, auto bary, double sign) {
        for (int p = 0; p < points; ++p, ++q) {
          const double* mq = pm + 8 * static_cast<size_t>(q);
          for (int k = 0; k < 3; ++k) {
            const double w = sign * bary(p)[k];
            for (int c = 0; c < 8; ++c) acc[k][c] += w * mq[c];
          }
        }
      };
      auto flush = [&](int e, const std::array<Mat3, 3>* singular) {
        for (int k = 0; k < 3; ++k) {
          double* b = &block_[6 * static_cast<size_t>(slot[k])];
          for (int c = 0; c < 6; ++c) b[c] += acc[k][c];
        }
        if (singular) {
          const int k0 = tri_(e, 0) == i ? 0 : (tri_(e, 1) == i ? 1 : 2);
          for (int k = 0; k < 3; ++k) add(&block_[6 * static_cast<size_t>(slot[(k0 + k) % 3])], 1.0, (*singular)[static_cast<size_t>(k)]);
        }
        slot += 3;
      };
      auto far = [&](int p) { return far_bary[p]; };
      for (int e : lists_.touching(i)) {
        std::fill(&acc[0][0], &acc[0][0] + 24, 0.0);
        add_points(3, far, -1.0);
        if (surface_.curved()) {
          const int k0 = tri_(e, 0) == i ? 0 : (tri_(e, 1) == i ? 1 : 2);
          const auto Ms = singular_element_double_layer(surface_.element(x, e, k0), rule_, rule_u_);
          flush(e, &Ms);
        } else {
          flush(e, nullptr);
        }
      }
      for (int e : lists_.ring(i)) {
        std::fill(&acc[0][0], &acc[0][0] + 24, 0.0);
        add_points(7, [](int p) { return kDunavant7[p]; }, 1.0);
        add_points(3, far, -1.0);
        flush(e, nullptr);
      }
      for (int e : lists_.band(i)) {
        std::fill(&acc[0][0], &acc[0][0] + 24, 0.0);
        add_points(3, [](int p) { return kGaussBary[p]; }, 1.0);
        add_points(3, far, -1.0);
        flush(e, nullptr);
      }
      // Scale, then the diagonal ½ I − D̃[1](x_i): the far field of the unit constants plus the row sums.
      double* Dg = &diagonal_[6 * static_cast<size_t>(i)];
      const double* f = &unit_far_[6 * static_cast<size_t>(i)];
      for (int k = 0; k < 6; ++k) Dg[k] = (k < 3 ? 0.5 : 0.0) - f[k];
      for (int b = block_start_[i]; b < block_start_[i + 1]; ++b)
        for (int k = 0; k < 6; ++k) {
          block_[6 * static_cast<size_t>(b) + k] *= kInv8Pi;
          Dg[k] -= block_[6 * static_cast<size_t>(b) + k];
        }
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

void DoubleLayer::apply(const Points& u, Points& out) {
  if (u.rows() != n_nodes_ || x_.rows() != n_nodes_)
    throw std::invalid_argument("double layer: set_surface() first, and one row of u per node");
  Stopwatch clock, total;
  const Eigen::Index ns = far_field_sources();
  fill_far_densities(u);
  clock.lap(times_, Phase::BieSources);
  out.resize(n_nodes_, 3);
  if (fmm_)
    fmm_->evaluate(density_.data(), out.data());
  else
    fmm::direct_sum<fmm::Stresslet, 1, false>(src_.data(), static_cast<std::size_t>(ns), density_.data(), x_.data(),
                                              static_cast<std::size_t>(n_nodes_), out.data(), threads_);
  clock.lap(times_, Phase::BieFar);
  add_near_field(u, out);
  clock.lap(times_, Phase::BieNear);
  apply_seconds_ += total.seconds();
  ++applications_;
}

}  // namespace capsflow
