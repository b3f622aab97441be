#include "capsflow/core/bie/single_layer.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <fmt/core.h>

#include <stdexcept>

#include "capsflow/fmm/calibration.hpp"
#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/direct_sum_mixed.hpp"
#include "capsflow/fmm/fmm.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow {

namespace {
constexpr double kInv8Pi = fmm::Stokeslet::scale();
}  // namespace

namespace {
int ring_layers(const SingleLayerOptions& o) { return o.near_ring_depth < 0 ? 0 : near_ring_layers(o); }
}  // namespace

SingleLayer::SingleLayer(const Triangles& triangles, Eigen::Index n_nodes, const SingleLayerOptions& opt)
    : tri_(triangles),
      n_nodes_(n_nodes),
      opt_(opt),
      threads_(layer_threads(opt)),
      far_rule_(far_field_rule(opt)),
      rule_(opt.singular_points),
      rule_u_(opt.geometry == SurfaceGeometry::Curved ? opt.singular_radial_points : 1),
      lists_(triangles, n_nodes, ring_layers(opt), corrected_layers(opt, ring_layers(opt), kAutoCorrectedLayers)),
      surface_(triangles, opt.geometry),
      source_slots_(far_field_source_slots(lists_, triangles.rows(), far_rule_ == FarFieldRule::EdgeMidpoints)) {
  if (opt.singular_radial_points > 16)
    throw std::invalid_argument("singular_radial_points: at most 16 Gauss points in u");
  const std::size_t m = static_cast<std::size_t>(tri_.rows());
  backend_ = choose_backend(opt.backend, FarFieldKernel::SingleLayer, far_field_sources(), n_nodes, opt.tolerance, &reason_);
  mixed_precision_ = uses_mixed_precision(backend_, opt.tolerance);
  if (backend_ == FarFieldBackend::Fmm) {
    fmm::FmmOptions fo;
    // The FMM calibration is in relative L2 error over targets; capsflow promises the tolerance
    // relative to max |v| at every node (max norm), so ask the FMM for a safety margin.
    fo.tolerance = kFmmToleranceMargin * opt.tolerance;
    fo.order = opt.fmm_order;
    fo.leaf_size = opt.fmm_leaf_size;
    fo.threads = threads_;
    fmm_ = std::make_unique<fmm::Fmm<fmm::Stokeslet>>(fo);
  }
  src_.resize(3 * source_slots_.size());
  strength_.resize(3 * source_slots_.size());
  far_block_.resize(m);
  if (opt.near_ring_depth == 0 && lists_.ring_layers() > 0) ring_block_.resize(m);
  batches_.resize(static_cast<size_t>(threads_));
}

SingleLayer::~SingleLayer() = default;

int SingleLayer::fmm_order() const { return fmm_ ? fmm_->order() : 0; }
int SingleLayer::fmm_leaf_size() const { return fmm_ ? fmm_->leaf_size() : 0; }

void SingleLayer::build_sources(const Points& x, const Points& q) {
  surface_.update(x, threads_);
  const Eigen::Index m = tri_.rows(), n_src = far_field_sources();
  const auto& far_bary = far_rule_ == FarFieldRule::EdgeMidpoints ? kEdgeMidpointBary : kGaussBary;
  const bool band = lists_.corrected_layers() > lists_.ring_layers();
  // A rule point (barycentrics l, weight w over the reference triangle) of element e as a
  // Stokeslet term: position y, force w J q(y).
  auto rule_point = [&](const QuadraticTriangle& T, Eigen::Index e, const double* l, double w, Vec3& y, Vec3& f) {
    y = T.position(l[1], l[2]);
    const double wj = w * T.jacobian(l[1], l[2]);
    for (int d = 0; d < 3; ++d) f[d] = wj * (l[0] * q(tri_(e, 0), d) + l[1] * q(tri_(e, 1), d) + l[2] * q(tri_(e, 2), d));
  };
#pragma omp parallel num_threads(threads_)
  {
    Vec3 y, f;
#pragma omp for schedule(dynamic, 256)
    for (Eigen::Index e = 0; e < m; ++e) {
      const QuadraticTriangle T = surface_.element(x, e, 0);
      StokesletBlock& fb = far_block_[static_cast<size_t>(e)];
      for (int k = 0; k < 3; ++k) {  // the far-field rule (degree 2, weights 1/6 of the Jacobian), negated
        rule_point(T, e, far_bary[k], 1.0 / 6.0, y, f);
        fb.set(kFarLane + k, y, -f);
      }
      if (band)
        for (int g = 0; g < 3; ++g) {
          rule_point(T, e, kGaussBary[g], 1.0 / 6.0, y, f);
          fb.set(kBandLane + g, y, f);
        }
      if (!ring_block_.empty())  // Dunavant's 7 points: computed once here, used by the ~18 nodes of whose ring e is part
        for (int k = 0; k < 7; ++k) {
          rule_point(T, e, kDunavant7[k], 0.5 * kDunavant7[k][3], y, f);
          ring_block_[static_cast<size_t>(e)].set(k, y, f);
        }
    }
    // Each source: at its first slot's point, with the sum of its slots' forces (both elements'
    // shares of an edge's midpoint); its other slot takes the same position, so that the near
    // field subtracts exactly what the far field added.
#pragma omp for schedule(dynamic, 256)
    for (Eigen::Index source = 0; source < n_src; ++source) {
      const auto& s = source_slots_[static_cast<size_t>(source)];
      const StokesletBlock& b0 = far_block_[static_cast<size_t>(s[0] / 3)];
      const int l0 = kFarLane + s[0] % 3;
      for (int d = 0; d < 3; ++d) {
        src_[static_cast<size_t>(3 * source + d)] = b0.y[d][l0];
        strength_[static_cast<size_t>(3 * source + d)] = -b0.f[d][l0];
      }
      if (s[1] < 0) continue;
      StokesletBlock& b1 = far_block_[static_cast<size_t>(s[1] / 3)];
      const int l1 = kFarLane + s[1] % 3;
      for (int d = 0; d < 3; ++d) {
        b1.y[d][l1] = b0.y[d][l0];
        strength_[static_cast<size_t>(3 * source + d)] -= b1.f[d][l1];
      }
    }
  }
}

void SingleLayer::far_field(const double* targets, Eigen::Index n_targets, double* out, bool targets_are_nodes) {
  const std::size_t n_src = src_.size() / 3;
  if (backend_ == FarFieldBackend::Fmm) {
    fmm_->setup(src_.data(), n_src, targets, static_cast<std::size_t>(n_targets));
    fmm_->evaluate(strength_.data(), out);
  } else if (targets_are_nodes && mixed_precision_) {
    fmm::stokeslet_direct_sum_mixed(src_.data(), n_src, strength_.data(), targets, static_cast<std::size_t>(n_targets), out,
                                    threads_);
  } else if (targets_are_nodes) {
    // Edge midpoints and Gauss points never coincide with a node: no r = 0 test, and one Newton
    // step after the hardware rsqrt (≤ 6e-9 per pair, ~1e-9 on the sum; far below the smallest tolerance a scene
    // accepts, 1e-8): 15–20 % faster than full precision.
    fmm::direct_sum<fmm::Stokeslet, 1, false>(src_.data(), n_src, strength_.data(), targets,
                                              static_cast<std::size_t>(n_targets), out, threads_);
  } else {
    fmm::direct_sum<fmm::Stokeslet>(src_.data(), n_src, strength_.data(), targets, static_cast<std::size_t>(n_targets), out,
                                    threads_);
  }
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

void SingleLayer::check_far_field(const Points& x, const Points& far) {
  const std::size_t n = static_cast<std::size_t>(n_nodes_);
  direct_scratch_.resize(3 * n);
  // Full double precision and the r = 0 mask: the reference must not share the fast paths of
  // far_field() (one-Newton rsqrt, single-precision pairs) it is meant to check.
  fmm::direct_sum<fmm::Stokeslet>(src_.data(), src_.size() / 3, strength_.data(), x.data(), n, direct_scratch_.data(),
                                  threads_);
  checks_.add(compare_far_field(far.data(), direct_scratch_.data(), n, 3, evaluations_), opt_.tolerance);
}

void SingleLayer::apply(const Points& x, const Points& q, Points& u) {
  if (x.rows() != n_nodes_ || q.rows() != n_nodes_)
    throw std::invalid_argument("single layer: positions and load must have one row per node");
  Stopwatch clock;
  build_sources(x, q);
  clock.lap(times_, Phase::BieSources);
  u.resize(n_nodes_, 3);
  far_field(x.data(), n_nodes_, u.data(), true);
  clock.lap(times_, Phase::BieFar);
  if (opt_.verify_every > 0 && evaluations_ % opt_.verify_every == 0) {
    check_far_field(x, u);
    clock.lap(times_, Phase::BieVerify);
  }
  correct_near_field(x, q, u);
  clock.lap(times_, Phase::BieNear);
  ++evaluations_;
}

}  // namespace capsflow
