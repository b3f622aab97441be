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
constexpr double kFmmToleranceMargin = 0.25;
}  // namespace

SingleLayer::SingleLayer(const Triangles& triangles, Eigen::Index n_nodes, const SingleLayerOptions& opt)
    : tri_(triangles),
      n_nodes_(n_nodes),
      opt_(opt),
      curved_(opt.geometry == SurfaceGeometry::Curved),
      rule_(opt.singular_points),
      rule_u_(curved_ ? opt.singular_radial_points : 1) {
  if (opt.singular_radial_points > 16)
    throw std::invalid_argument("singular_radial_points: at most 16 Gauss points in u");
  backend_ = choose_backend(opt.backend, tri_.rows(), n_nodes, opt.tolerance, &reason_);
  mixed_precision_ = uses_mixed_precision(backend_, opt.tolerance);
  if (backend_ == FarFieldBackend::Fmm) {
    fmm::FmmOptions fo;
    // The FMM calibration is in relative L2 error over targets; capsflow promises the tolerance
    // relative to max |v| at every node (max norm), so ask the FMM for a safety margin.
    fo.tolerance = kFmmToleranceMargin * opt.tolerance;
    fo.order = opt.fmm_order;
    fo.threads = opt.threads;
    fmm_ = std::make_unique<fmm::Fmm<fmm::Stokeslet>>(fo);
  }
  // Node → element adjacency (CSR), built once: the mesh connectivity never changes.
  node_elem_start_.assign(static_cast<size_t>(n_nodes + 1), 0);
  for (Eigen::Index e = 0; e < tri_.rows(); ++e)
    for (int k = 0; k < 3; ++k) ++node_elem_start_[static_cast<size_t>(tri_(e, k)) + 1];
  for (Eigen::Index i = 0; i < n_nodes; ++i) node_elem_start_[i + 1] += node_elem_start_[i];
  node_elem_.resize(static_cast<size_t>(node_elem_start_.back()));
  std::vector<int> fill(node_elem_start_.begin(), node_elem_start_.end() - 1);
  for (Eigen::Index e = 0; e < tri_.rows(); ++e)
    for (int k = 0; k < 3; ++k) node_elem_[static_cast<size_t>(fill[tri_(e, k)]++)] = static_cast<int>(e);
  // Near ring: the elements touching a vertex within `near_ring_layers` edge hops of the node,
  // except the node's own (layer 1 = the elements sharing a vertex with a touching element).
  ring_start_.assign(1, 0);
  const int layers = opt.near_ring_layers > 0 ? opt.near_ring_layers : (curved_ ? 2 : 1);
  std::vector<int> ring, verts, next;
  for (Eigen::Index i = 0; i < n_nodes; ++i) {
    ring.clear();
    verts.assign(1, static_cast<int>(i));
    for (int layer = 0; opt.near_ring_depth >= 0 && layer < layers; ++layer) {
      next.clear();  // vertices one hop further
      for (int v : verts)
        for (int t = node_elem_start_[v]; t < node_elem_start_[v + 1]; ++t)
          for (int k = 0; k < 3; ++k) next.push_back(tri_(node_elem_[static_cast<size_t>(t)], k));
      std::sort(next.begin(), next.end());
      next.erase(std::unique(next.begin(), next.end()), next.end());
      verts.swap(next);
    }
    if (opt.near_ring_depth >= 0)
      for (int v : verts)
        for (int t = node_elem_start_[v]; t < node_elem_start_[v + 1]; ++t) {
          const int e = node_elem_[static_cast<size_t>(t)];
          if (tri_(e, 0) != i && tri_(e, 1) != i && tri_(e, 2) != i) ring.push_back(e);
        }
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
    ring_.insert(ring_.end(), ring.begin(), ring.end());
    ring_start_.push_back(static_cast<int>(ring_.size()));
  }
  src_.resize(static_cast<size_t>(9 * tri_.rows()));
  strength_.resize(static_cast<size_t>(9 * tri_.rows()));
  mid_.resize(static_cast<size_t>(3 * tri_.rows()));
  if (opt.near_ring_depth == 0 && !ring_.empty()) {
    ring_src_.resize(static_cast<size_t>(21 * tri_.rows()));
    ring_strength_.resize(static_cast<size_t>(21 * tri_.rows()));
  }
  batches_.resize(static_cast<size_t>(std::max(opt.threads, omp_get_max_threads())));
}

SingleLayer::~SingleLayer() = default;

int SingleLayer::fmm_order() const { return fmm_ ? fmm_->order() : 0; }

void SingleLayer::build_surface(const Points& x) {
  if (!curved_) return;  // flat facets need no midpoints (element() builds them)
  vertex_normals_max(x, tri_, normals_);
  const Eigen::Index m = tri_.rows();
#pragma omp parallel for schedule(static)
  for (Eigen::Index e = 0; e < m; ++e)
    for (int k = 0; k < 3; ++k) {
      const int a = tri_(e, k), b = tri_(e, (k + 1) % 3);
      mid_[static_cast<size_t>(3 * e + k)] = hermite_edge_midpoint(x.row(a).transpose(), x.row(b).transpose(),
                                                                   normals_.row(a).transpose(), normals_.row(b).transpose());
    }
}

QuadraticTriangle SingleLayer::element(const Points& x, Eigen::Index e, int first) const {
  const int k1 = (first + 1) % 3, k2 = (first + 2) % 3;
  const Vec3* m = &mid_[static_cast<size_t>(3 * e)];
  if (!curved_)
    return QuadraticTriangle::flat(x.row(tri_(e, first)).transpose(), x.row(tri_(e, k1)).transpose(),
                                   x.row(tri_(e, k2)).transpose());
  return QuadraticTriangle(x.row(tri_(e, first)).transpose(), x.row(tri_(e, k1)).transpose(), x.row(tri_(e, k2)).transpose(),
                           m[first], m[k1], m[k2]);
}

void SingleLayer::build_sources(const Points& x, const Points& q) {
  build_surface(x);
  const Eigen::Index m = tri_.rows();
#pragma omp parallel for schedule(static)
  for (Eigen::Index e = 0; e < m; ++e) {
    const int a = tri_(e, 0), b = tri_(e, 1), c = tri_(e, 2);
    const QuadraticTriangle T = element(x, e, 0);
    for (int g = 0; g < 3; ++g) {
      const double* l = kGaussBary[g];
      const Vec3 y = T.position(l[1], l[2]);
      const double w = T.jacobian(l[1], l[2]) / 6.0;  // reference-triangle area 1/2, three equal weights
      const size_t o = static_cast<size_t>(9 * e + 3 * g);
      for (int d = 0; d < 3; ++d) {
        src_[o + d] = y[d];
        strength_[o + d] = w * (l[0] * q(a, d) + l[1] * q(b, d) + l[2] * q(c, d));
      }
    }
    if (ring_src_.empty()) continue;
    // Dunavant 7-point sources for the near ring: computed once here, used by ~10–25 nodes each.
    for (int k = 0; k < 7; ++k) {
      const double* r = kDunavant7[k];
      const Vec3 y = T.position(r[1], r[2]);
      const double w = 0.5 * r[3] * T.jacobian(r[1], r[2]);
      const size_t o = static_cast<size_t>(21 * e + 3 * k);
      for (int d = 0; d < 3; ++d) {
        ring_src_[o + d] = y[d];
        ring_strength_[o + d] = w * (r[0] * q(a, d) + r[1] * q(b, d) + r[2] * q(c, d));
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
                                    opt_.threads);
  } else if (targets_are_nodes) {
    // Gauss points are interior to the elements, so they never coincide with a node: no r = 0
    // test, and one Newton step after the hardware rsqrt (≤ 6e-9 per pair, ~1e-9 on the sum; far
    // below the smallest tolerance a scene accepts, 1e-8): 15–20 % faster than full precision.
    fmm::direct_sum<fmm::Stokeslet, 1, false>(src_.data(), n_src, strength_.data(), targets,
                                              static_cast<std::size_t>(n_targets), out, opt_.threads);
  } else {
    fmm::direct_sum<fmm::Stokeslet>(src_.data(), n_src, strength_.data(), targets, static_cast<std::size_t>(n_targets), out,
                                    opt_.threads);
  }
}

void SingleLayer::correct_touching_elements(const Points& x, const Points& q, Points& u) {
  // Per node: gather every local term (exact integrals of the touching elements and the near
  // ring, minus the Gauss-point sources the far field added for them) into one batch, then sum.
#pragma omp parallel
  {
    StokesletBatch& batch = batches_[static_cast<size_t>(omp_get_thread_num())];
    auto subtract_far_field = [&](const Vec3& xi, int e) {
      for (int g = 0; g < 3; ++g) {
        const size_t o = static_cast<size_t>(9 * e + 3 * g);
        batch.push(xi - Vec3(src_[o], src_[o + 1], src_[o + 2]), -Vec3(strength_[o], strength_[o + 1], strength_[o + 2]));
      }
    };
#pragma omp for schedule(static)
    for (Eigen::Index i = 0; i < n_nodes_; ++i) {
      const Vec3 xi = x.row(i).transpose();
      batch.clear();
      Vec3 local = Vec3::Zero();  // closed-form and matrix-valued terms
      for (int s = node_elem_start_[i]; s < node_elem_start_[i + 1]; ++s) {
        const int e = node_elem_[static_cast<size_t>(s)];
        const int k0 = tri_(e, 0) == i ? 0 : (tri_(e, 1) == i ? 1 : 2);
        local += singular_element_apply(batch, element(x, e, k0), q.row(i).transpose(),
                                        q.row(tri_(e, (k0 + 1) % 3)).transpose(), q.row(tri_(e, (k0 + 2) % 3)).transpose(), rule_,
                                        rule_u_);
        subtract_far_field(xi, e);
      }
      for (int s = ring_start_[i]; s < ring_start_[i + 1]; ++s) {
        const int e = ring_[static_cast<size_t>(s)];
        if (opt_.near_ring_depth == 0) {
          const double* y = &ring_src_[static_cast<size_t>(21 * e)];
          const double* f = &ring_strength_[static_cast<size_t>(21 * e)];
          for (int k = 0; k < 7; ++k, y += 3, f += 3) batch.push(xi[0] - y[0], xi[1] - y[1], xi[2] - y[2], f[0], f[1], f[2]);
        } else {
          const auto S = refined_element_integral(xi, element(x, e, 0), opt_.near_ring_depth);
          for (int k = 0; k < 3; ++k) local += S[k] * q.row(tri_(e, k)).transpose();
        }
        subtract_far_field(xi, e);
      }
      u.row(i) += kInv8Pi * (batch.sum() + local).transpose();
    }
  }
}

void SingleLayer::check_far_field(const Points& x, const Points& far) {
  const std::size_t n = static_cast<std::size_t>(n_nodes_);
  direct_scratch_.resize(3 * n);
  // Full double precision and the r = 0 mask: the reference must not share the fast paths of
  // far_field() (one-Newton rsqrt, single-precision pairs) it is meant to check.
  fmm::direct_sum<fmm::Stokeslet>(src_.data(), src_.size() / 3, strength_.data(), x.data(), n, direct_scratch_.data(),
                                  opt_.threads);
  double max_ref = 0, max_diff = 0, sum_sq = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Index r = static_cast<Eigen::Index>(i);
    const Vec3 ref(direct_scratch_[3 * i], direct_scratch_[3 * i + 1], direct_scratch_[3 * i + 2]);
    const double d = (far.row(r).transpose() - ref).norm();
    max_ref = std::max(max_ref, ref.norm());
    max_diff = std::max(max_diff, d);
    sum_sq += d * d;
  }
  last_check_.evaluation = evaluations_;
  // A zero load gives a zero far field in both sums: report agreement rather than 0/0.
  last_check_.max_relative = max_ref > 0 ? max_diff / max_ref : 0.0;
  last_check_.rms_relative = max_ref > 0 ? std::sqrt(sum_sq / static_cast<double>(n)) / max_ref : 0.0;
  ++checks_;
  if (checks_ == 1 || last_check_.max_relative > worst_check_.max_relative) worst_check_ = last_check_;
  worst_rms_ = std::max(worst_rms_, last_check_.rms_relative);
  if (last_check_.max_relative > opt_.tolerance) ++checks_above_;
}

void SingleLayer::apply(const Points& x, const Points& q, Points& u) {
  if (x.rows() != n_nodes_ || q.rows() != n_nodes_)
    throw std::invalid_argument("single layer: positions and load must have one row per node");
  const int threads = opt_.threads > 0 ? opt_.threads : omp_get_max_threads();
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  if (batches_.size() < static_cast<size_t>(threads)) batches_.resize(static_cast<size_t>(threads));
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
  correct_touching_elements(x, q, u);
  clock.lap(times_, Phase::BieNear);
  ++evaluations_;
  omp_set_num_threads(saved);
}

}  // namespace capsflow
