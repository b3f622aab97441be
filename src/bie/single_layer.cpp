#include "capsflow/core/bie/single_layer.hpp"

#include <omp.h>

#include <stdexcept>

#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow {

namespace {
constexpr double kInv8Pi = fmm::Stokeslet::scale();
int ring_layers(const SingleLayerOptions& o) { return o.near_ring_depth < 0 ? 0 : near_ring_layers(o); }
}  // namespace

SingleLayer::SingleLayer(const Triangles& triangles, Eigen::Index n_nodes, const SingleLayerOptions& opt)
    : tri_(triangles),
      n_nodes_(n_nodes),
      opt_(opt),
      threads_(layer_threads(opt)),
      rule_(opt.singular_points),
      rule_u_(opt.geometry == SurfaceGeometry::Curved ? opt.singular_radial_points : 1),
      lists_(triangles, n_nodes, ring_layers(opt), corrected_layers(opt, ring_layers(opt), kAutoCorrectedLayers)),
      surface_(triangles, opt.geometry),
      far_(lists_, triangles.rows(), n_nodes, opt, threads_) {
  if (opt.singular_radial_points > 16)
    throw std::invalid_argument("singular_radial_points: at most 16 Gauss points in u");
  const std::size_t m = static_cast<std::size_t>(tri_.rows());
  mixed_precision_ = uses_mixed_precision(opt.tolerance);
  far_block_.resize(m);
  if (opt.near_ring_depth == 0 && lists_.ring_layers() > 0) ring_block_.resize(m);
  batches_.resize(static_cast<size_t>(threads_));
}

SingleLayer::~SingleLayer() = default;

void SingleLayer::build_sources(const Points& x, const Points& q) {
  surface_.update(x, threads_);
  const bool band = lists_.corrected_layers() > lists_.ring_layers();
  // A rule point (barycentrics l, weight w over the reference triangle) of element e as a
  // Stokeslet term: position y, force f = w J q(y).
  auto rule_point = [&](const QuadraticTriangle& T, Eigen::Index e, const double* l, double w, double* y, double* f) {
    const Vec3 p = T.position(l[1], l[2]);
    const double wj = w * T.jacobian(l[1], l[2]);
    for (int d = 0; d < 3; ++d)
      y[d] = p[d], f[d] = wj * (l[0] * q(tri_(e, 0), d) + l[1] * q(tri_(e, 1), d) + l[2] * q(tri_(e, 2), d));
  };
  // The element's own near-field rules: the band's 3-point rule, and Dunavant's 7 points of the
  // ring (computed once here, used by the ~18 nodes of whose ring e is part).
  auto near_rules = [&](const QuadraticTriangle& T, Eigen::Index e) {
    double y[3], f[3];
    if (band)
      for (int g = 0; g < 3; ++g) {
        rule_point(T, e, kGaussBary[g], 1.0 / 6.0, y, f);
        far_block_[static_cast<size_t>(e)].set(kBandLane + g, Vec3(y[0], y[1], y[2]), Vec3(f[0], f[1], f[2]));
      }
    if (!ring_block_.empty())
      for (int k = 0; k < 7; ++k) {
        rule_point(T, e, kDunavant7[k], 0.5 * kDunavant7[k][3], y, f);
        ring_block_[static_cast<size_t>(e)].set(k, Vec3(y[0], y[1], y[2]), Vec3(f[0], f[1], f[2]));
      }
  };
  far_.place(x, surface_, rule_point, near_rules);
  // The far-field terms negated, at the positions the far field summed them (the two sides of an
  // edge at the one source's), so that the near field subtracts exactly what the far field added.
  const Eigen::Index m = tri_.rows();
#pragma omp parallel for schedule(static) num_threads(threads_)
  for (Eigen::Index e = 0; e < m; ++e)
    for (int k = 0; k < 3; ++k) {
      const double* y = far_.slot_position(static_cast<size_t>(3 * e + k));
      const double* f = far_.slot_value(static_cast<size_t>(3 * e + k));
      far_block_[static_cast<size_t>(e)].set(kFarLane + k, Vec3(y[0], y[1], y[2]), -Vec3(f[0], f[1], f[2]));
    }
}

Vec3 SingleLayer::element_far_terms(Eigen::Index e, const Vec3& p) const {
  Vec3 sum = Vec3::Zero();
  for (int k = 0; k < 3; ++k) {
    const double* y = far_.slot_position(static_cast<size_t>(3 * e + k));
    const double* f = far_.slot_value(static_cast<size_t>(3 * e + k));
    const Vec3 r = p - Vec3(y[0], y[1], y[2]);
    if (r.squaredNorm() > 0) sum += stokeslet_apply(r, Vec3(f[0], f[1], f[2]));
  }
  return sum;
}

void SingleLayer::far_field(double* out, bool at_nodes) {
  if (far_.backend() == FarFieldBackend::Fmm)
    far_.evaluate(FarField<fmm::Stokeslet>::kMainFmm, far_.values(), out);
  else  // points off the surface may coincide with a source: the exact pairs there
    far_.direct(far_.values(), out, !at_nodes ? DirectPairs::Exact : mixed_precision_ ? DirectPairs::Single : DirectPairs::Fast);
}

void SingleLayer::correct_near_field(const Points& x, const Points& q, Points& u) {
  // Per node: the exact integrals of the touching elements (closed form, plus a batch of Duffy
  // points on curved elements), the ring's and the band's rules, minus the far-field terms of all
  // these elements (their blocks' negated lanes), accumulated lane by lane.
  using V = fmm::simd::VecD;
#pragma omp parallel num_threads(threads_)
  {
    StokesletBatch& batch = batches_[static_cast<size_t>(omp_get_thread_num())];
    // In chunks: equal static halves of the nodes did not take equal time (cpu/wall 1.69 against
    // 1.98 at 81 920 elements, perf/RESULTS.md §1.1); each node writes only its own row.
#pragma omp for schedule(dynamic, 64)
    for (Eigen::Index i = 0; i < n_nodes_; ++i) {
      const double xi[3] = {x(i, 0), x(i, 1), x(i, 2)};
      V acc[3] = {V(0.0), V(0.0), V(0.0)};
      batch.clear();
      Vec3 local = Vec3::Zero();  // closed-form and matrix-valued terms
      for (int e : lists_.touching(i)) {
        const int k0 = tri_(e, 0) == i ? 0 : (tri_(e, 1) == i ? 1 : 2);
        local += singular_element_apply(batch, surface_.element(x, e, k0), q.row(i).transpose(),
                                        q.row(tri_(e, (k0 + 1) % 3)).transpose(), q.row(tri_(e, (k0 + 2) % 3)).transpose(), rule_,
                                        rule_u_);
        far_block_[static_cast<size_t>(e)].accumulate(xi, kFarLane, 3, acc);
      }
      for (int e : lists_.ring(i)) {
        if (!ring_block_.empty()) {
          ring_block_[static_cast<size_t>(e)].accumulate(xi, 0, 7, acc);
        } else {
          const auto S = refined_element_integral(x.row(i).transpose(), surface_.element(x, e, 0), opt_.near_ring_depth);
          for (int k = 0; k < 3; ++k) local += S[k] * q.row(tri_(e, k)).transpose();
        }
        far_block_[static_cast<size_t>(e)].accumulate(xi, kFarLane, 3, acc);
      }
      for (int e : lists_.band(i)) far_block_[static_cast<size_t>(e)].accumulate(xi, kBandLane, 6, acc);
      u.row(i) += kInv8Pi * (lane_sum(acc) + batch.sum() + local).transpose();
    }
  }
}

void SingleLayer::apply(const Points& x, const Points& q, Points& u) {
  if (x.rows() != n_nodes_ || q.rows() != n_nodes_)
    throw std::invalid_argument("single layer: positions and load must have one row per node");
  Stopwatch clock;
  build_sources(x, q);
  clock.lap(times_, Phase::BieSources);
  u.resize(n_nodes_, 3);
  far_.set_targets(x.data(), n_nodes_);
  far_field(u.data(), true);
  clock.lap(times_, Phase::BieFar);
  if (far_.check_due(evaluations_)) {
    far_.record(far_.compare_with_direct(far_.values(), u.data(), evaluations_));
    clock.lap(times_, Phase::BieVerify);
  }
  correct_near_field(x, q, u);
  clock.lap(times_, Phase::BieNear);
  ++evaluations_;
}

}  // namespace capsflow
