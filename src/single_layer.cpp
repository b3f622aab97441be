#include "capsflow/core/single_layer.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <fmt/core.h>

#include "capsflow/fmm/calibration.hpp"
#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/fmm.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
constexpr double kInv8Pi = 1.0 / (8.0 * M_PI);
constexpr double kFmmToleranceMargin = 0.25;
}  // namespace

const char* to_string(FarFieldBackend b) { return b == FarFieldBackend::Fmm ? "fmm" : "direct"; }

FarFieldBackend choose_backend(const std::string& requested, Eigen::Index n_elements, Eigen::Index n_nodes,
                               double tolerance, std::string* reason) {
  const std::size_t n_src = static_cast<std::size_t>(3 * n_elements), n_trg = static_cast<std::size_t>(n_nodes);
  std::string why;
  FarFieldBackend b;
  if (requested == "direct" || requested == "fmm") {
    b = requested == "fmm" ? FarFieldBackend::Fmm : FarFieldBackend::Direct;
    why = fmt::format("forced by the scene (fluid.backend = \"{}\")", requested);
  } else if (requested == "auto") {
    const bool direct = fmm::prefer_direct(n_src, n_trg, tolerance);
    b = direct ? FarFieldBackend::Direct : FarFieldBackend::Fmm;
    why = fmt::format("auto: {} sources × {} targets is {} the measured FMM/direct crossover at tolerance {:g} ({} points)",
                      n_src, n_trg, direct ? "below" : "above", tolerance, fmm::direct_crossover(tolerance));
  } else {
    throw std::invalid_argument("unknown boundary-integral back end '" + requested + "' (auto, fmm or direct)");
  }
  if (reason) *reason = why;
  return b;
}

SingleLayer::SingleLayer(const Triangles& triangles, Eigen::Index n_nodes, const SingleLayerOptions& opt)
    : tri_(triangles), n_nodes_(n_nodes), opt_(opt), rule_(opt.singular_points) {
  backend_ = choose_backend(opt.backend, tri_.rows(), n_nodes, opt.tolerance, &reason_);
  if (backend_ == FarFieldBackend::Fmm) {
    fmm::FmmOptions fo;
    // The FMM calibration is in relative L2 error over targets; capsflow promises the tolerance
    // relative to max |v| at every node (max norm), so ask the FMM for a safety margin.
    fo.tolerance = kFmmToleranceMargin * opt.tolerance;
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
  // Near ring: elements sharing a vertex with a touching element, but not touching the node.
  ring_start_.assign(1, 0);
  std::vector<int> ring;
  for (Eigen::Index i = 0; i < n_nodes; ++i) {
    ring.clear();
    if (opt.near_ring_depth >= 0)
      for (int s = node_elem_start_[i]; s < node_elem_start_[i + 1]; ++s)
        for (int k = 0; k < 3; ++k) {
          const int v = tri_(node_elem_[static_cast<size_t>(s)], k);
          for (int t = node_elem_start_[v]; t < node_elem_start_[v + 1]; ++t) {
            const int e = node_elem_[static_cast<size_t>(t)];
            if (tri_(e, 0) != i && tri_(e, 1) != i && tri_(e, 2) != i) ring.push_back(e);
          }
        }
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
    ring_.insert(ring_.end(), ring.begin(), ring.end());
    ring_start_.push_back(static_cast<int>(ring_.size()));
  }
  src_.resize(static_cast<size_t>(9 * tri_.rows()));
  strength_.resize(static_cast<size_t>(9 * tri_.rows()));
}

SingleLayer::~SingleLayer() = default;

int SingleLayer::fmm_order() const { return fmm_ ? fmm_->order() : 0; }

void SingleLayer::build_sources(const Points& x, const Points& q) {
  const Eigen::Index m = tri_.rows();
#pragma omp parallel for schedule(static)
  for (Eigen::Index e = 0; e < m; ++e) {
    const int a = tri_(e, 0), b = tri_(e, 1), c = tri_(e, 2);
    const double w = 0.5 * (x.row(b) - x.row(a)).cross(x.row(c) - x.row(a)).norm() / 3.0;
    for (int g = 0; g < 3; ++g) {
      const double* l = kGaussBary[g];
      const size_t o = static_cast<size_t>(9 * e + 3 * g);
      for (int d = 0; d < 3; ++d) {
        src_[o + d] = l[0] * x(a, d) + l[1] * x(b, d) + l[2] * x(c, d);
        strength_[o + d] = w * (l[0] * q(a, d) + l[1] * q(b, d) + l[2] * q(c, d));
      }
    }
  }
}

void SingleLayer::far_field(const double* targets, Eigen::Index n_targets, double* out) {
  const std::size_t n_src = src_.size() / 3;
  if (backend_ == FarFieldBackend::Fmm) {
    fmm_->setup(src_.data(), n_src, targets, static_cast<std::size_t>(n_targets));
    fmm_->evaluate(strength_.data(), out);
  } else {
    fmm::direct_sum<fmm::Stokeslet>(src_.data(), n_src, strength_.data(), targets, static_cast<std::size_t>(n_targets), out,
                                    opt_.threads);
  }
}

void SingleLayer::correct_touching_elements(const Points& x, const Points& q, Points& u) const {
#pragma omp parallel for schedule(static)
  for (Eigen::Index i = 0; i < n_nodes_; ++i) {
    const Vec3 xi = x.row(i).transpose();
    Vec3 corr = Vec3::Zero();
    for (int s = node_elem_start_[i]; s < node_elem_start_[i + 1]; ++s) {
      const int e = node_elem_[static_cast<size_t>(s)];
      const int k0 = tri_(e, 0) == i ? 0 : (tri_(e, 1) == i ? 1 : 2);
      const int j = tri_(e, (k0 + 1) % 3), k = tri_(e, (k0 + 2) % 3);
      corr += singular_element_apply(xi, x.row(j).transpose(), x.row(k).transpose(), q.row(i).transpose(),
                                     q.row(j).transpose(), q.row(k).transpose(), rule_);
      for (int g = 0; g < 3; ++g) {  // remove what the far-field sum added for this element
        const size_t o = static_cast<size_t>(9 * e + 3 * g);
        const Vec3 y(src_[o], src_[o + 1], src_[o + 2]), f(strength_[o], strength_[o + 1], strength_[o + 2]);
        corr -= stokeslet_apply(xi - y, f);
      }
    }
    for (int s = ring_start_[i]; s < ring_start_[i + 1]; ++s) {
      const int e = ring_[static_cast<size_t>(s)];
      const int a = tri_(e, 0), b = tri_(e, 1), c = tri_(e, 2);
      if (opt_.near_ring_depth == 0)
        corr += near_element_apply(xi, x.row(a).transpose(), x.row(b).transpose(), x.row(c).transpose(), q.row(a).transpose(),
                                   q.row(b).transpose(), q.row(c).transpose());
      else {
        const auto S = refined_element_integral(xi, x.row(a).transpose(), x.row(b).transpose(), x.row(c).transpose(),
                                                opt_.near_ring_depth);
        corr += S[0] * q.row(a).transpose() + S[1] * q.row(b).transpose() + S[2] * q.row(c).transpose();
      }
      for (int g = 0; g < 3; ++g) {
        const size_t o = static_cast<size_t>(9 * e + 3 * g);
        corr -= stokeslet_apply(xi - Vec3(src_[o], src_[o + 1], src_[o + 2]), Vec3(strength_[o], strength_[o + 1], strength_[o + 2]));
      }
    }
    u.row(i) += kInv8Pi * corr.transpose();
  }
}

void SingleLayer::apply(const Points& x, const Points& q, Points& u) {
  if (x.rows() != n_nodes_ || q.rows() != n_nodes_)
    throw std::invalid_argument("single layer: positions and load must have one row per node");
  const int threads = opt_.threads > 0 ? opt_.threads : omp_get_max_threads();
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  auto t0 = std::chrono::steady_clock::now();
  build_sources(x, q);
  timings_.sources += seconds_since(t0);
  u.resize(n_nodes_, 3);
  t0 = std::chrono::steady_clock::now();
  far_field(x.data(), n_nodes_, u.data());
  timings_.far += seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  correct_touching_elements(x, q, u);
  timings_.near += seconds_since(t0);
  ++timings_.evaluations;
  omp_set_num_threads(saved);
}

}  // namespace capsflow
