#include "capsflow/core/bie/identity_term_cache.hpp"

#include <algorithm>

namespace capsflow {

namespace {
// The guard for what the sample cannot see: a node whose corner value moved by more than
// kCornerJump in its frame since the refresh, and by more than kCornerOverSampled times the most
// any sampled node's did (a local jump between the samples, not the whole surface's motion, which
// the sample measures), forces a refresh. A time step's own motion at 81 920 elements and λ = 5
// moves corner values by up to 2e-3 within one RKC step while the extrapolation still matches the
// sample to the refresh pass's noise (docs/boundary-integral.md §4.7.5): hence the second condition.
constexpr double kCornerJump = 1e-3;
constexpr double kCornerOverSampled = 2.0;
// How far along the line through the last two refreshes E may be extrapolated, in units of their
// distance (the fit's s, clamped: beyond, the refresh pass's noise would be amplified).
constexpr double kExtrapolationRange[2] = {-1.0, 3.0};
// Along two secants (E1 − E0, E0 − E−1): coefficients within ±6 (noise amplified at most ~10×;
// what it does amplify the sample sees), and only where the secants are independent.
constexpr double kQuadraticRange[2] = {-6.0, 6.0};
constexpr double kSecantsIndependent = 1e-6;
constexpr size_t kRecord = 24;  // per node: E1, C1, E0, E−1 (6 each, symmetric)
constexpr size_t kCorner = 21;  // per node: C (6), R (9), C in the local frame (6)

// A node's reused error term in its local frame: E1 + s (E1 − E0) + s2 (E0 − E−1), from its record
// (E1, C1, E0, E−1).
inline Mat3 extrapolated_error(const double* record, double s, double s2 = 0) {
  const Mat3 E1 = symmetric_matrix(record);
  Mat3 E = E1;
  if (s != 0) E += s * (E1 - symmetric_matrix(record + 12));
  if (s2 != 0) E += s2 * (symmetric_matrix(record + 12) - symmetric_matrix(record + 18));
  return E;
}
}  // namespace

IdentityTermCache::IdentityTermCache(const Triangles& triangles, Eigen::Index n_nodes, const std::vector<int>& node_order,
                                     double tolerance, int threads)
    : n_nodes_(n_nodes),
      tolerance_(tolerance),
      threads_(threads),
      fans_(triangles, n_nodes),
      refreshed_(kRecord * static_cast<size_t>(n_nodes)),
      corner_(kCorner * static_cast<size_t>(n_nodes)) {
  const size_t stride = std::max<size_t>(1, node_order.size() / kSamples);
  for (size_t k = 0; k < node_order.size(); k += stride) samples_.push_back(node_order[k]);
  sample_error_.resize(samples_.size());
}

Mat3 IdentityTermCache::local_frame(const Points& x, Eigen::Index i) const {
  // Columns: tangent (towards the fan's first p), binormal, normal (area-weighted, outward).
  const Vec3 xi = x.row(i).transpose();
  Vec3 n = Vec3::Zero();
  for (int f = fans_.start[static_cast<size_t>(i)]; f < fans_.start[static_cast<size_t>(i) + 1]; ++f) {
    const CornerFacet& F = fans_.facets[static_cast<size_t>(f)];
    n += (x.row(F.p).transpose() - xi).cross(x.row(F.q).transpose() - xi);
  }
  n.normalize();
  const Vec3 p = x.row(fans_.facets[static_cast<size_t>(fans_.start[static_cast<size_t>(i)])].p).transpose() - xi;
  const Vec3 t = (p - p.dot(n) * n).normalized();
  Mat3 R;
  R.col(0) = t, R.col(1) = n.cross(t), R.col(2) = n;
  return R;
}

void IdentityTermCache::set_surface(const Points& x) {
  // Per node C, R and C in the local frame, and how far the surface moved since the last refresh:
  // the largest change of a node's local corner value, over all nodes and over the sample.
  const bool since = refresh_records_ > 0;
  double change = 0;
#pragma omp parallel for schedule(static) reduction(max : change) num_threads(threads_)
  for (Eigen::Index i = 0; i < n_nodes_; ++i) {
    const size_t k = static_cast<size_t>(i);
    const Mat3 R = local_frame(x, i), C = corner_double_layer(x, i, fans_);
    store_symmetric(C, &corner_[kCorner * k]);
    Eigen::Map<Mat3> frame(&corner_[kCorner * k + 6]);
    frame = R;
    const Mat3 local = R.transpose() * C * R;
    store_symmetric(local, &corner_[kCorner * k + 15]);
    if (since) change = std::max(change, (local - symmetric_matrix(&refreshed_[kRecord * k + 6])).norm());
  }
  double sampled = 0;
  if (since)
    for (const int i : samples_) {
      const size_t k = static_cast<size_t>(i);
      sampled = std::max(sampled, (symmetric_matrix(&corner_[kCorner * k + 15]) - symmetric_matrix(&refreshed_[kRecord * k + 6])).norm());
    }
  jumped_ = since && change > kCornerJump && change > kCornerOverSampled * sampled;
  extrapolation_ = extrapolation2_ = sampled_drift_ = 0;
}

bool IdentityTermCache::forced_refresh(bool on_trajectory, bool verify_now) const {
  if (refresh_records_ == 0 || jumped_) return true;
  return on_trajectory && verify_now;
}

double IdentityTermCache::sampled_drift(double s, double s2) const {
  double d = 0;
  for (size_t j = 0; j < samples_.size(); ++j)
    d = std::max(d, (sample_error_[j] - extrapolated_error(&refreshed_[kRecord * static_cast<size_t>(samples_[j])], s, s2)).norm());
  return d;
}

bool IdentityTermCache::measure(const std::vector<Mat3>& exact, bool on_trajectory) {
  // E at the samples in the local frames, and the reuse's value there: E1 + s (E1 − E0) + s2 (E0 − E−1),
  // s and s2 fitted to the sample by least squares (0 after a single refresh): of
  // now − E1 ≈ s d1 + s2 d2, d1 = E1 − E0, d2 = E0 − E−1, the normal equations' Gram matrix g and
  // right-hand side r.
  std::vector<Mat3>& now = sample_error_;
  double g11 = 0, g12 = 0, g22 = 0, r1 = 0, r2 = 0;
  for (size_t j = 0; j < samples_.size(); ++j) {
    const size_t k = static_cast<size_t>(samples_[j]);
    const Mat3 C = symmetric_matrix(&corner_[kCorner * k]), R = Eigen::Map<const Mat3>(&corner_[kCorner * k + 6]);
    now[j] = R.transpose() * (exact[j] - C) * R;
    if (refresh_records_ < 2) continue;
    const double* record = &refreshed_[kRecord * k];
    const Mat3 E1 = symmetric_matrix(record), E0 = symmetric_matrix(record + 12), d1 = E1 - E0;
    g11 += d1.squaredNorm(), r1 += ((now[j] - E1).array() * d1.array()).sum();
    if (refresh_records_ < 3) continue;
    const Mat3 d2 = E0 - symmetric_matrix(record + 18);
    g12 += (d1.array() * d2.array()).sum(), g22 += d2.squaredNorm(), r2 += ((now[j] - E1).array() * d2.array()).sum();
  }
  // The fit along one secant (s), and after three refreshes along two (s, s2: the quadratic
  // through them); the reuse takes whichever errs less at the sample.
  extrapolation_ = g11 > 0 ? std::clamp(r1 / g11, kExtrapolationRange[0], kExtrapolationRange[1]) : 0.0;
  extrapolation2_ = 0;
  double drift = sampled_drift(extrapolation_, 0);
  const double det = g11 * g22 - g12 * g12;
  if (refresh_records_ >= 3 && det > kSecantsIndependent * g11 * g22) {
    const double a = std::clamp((r1 * g22 - r2 * g12) / det, kQuadraticRange[0], kQuadraticRange[1]);
    const double b = std::clamp((g11 * r2 - g12 * r1) / det, kQuadraticRange[0], kQuadraticRange[1]);
    const double quadratic = sampled_drift(a, b);
    if (quadratic < drift) extrapolation_ = a, extrapolation2_ = b, drift = quadratic;
  }
  sampled_drift_ = drift;
  const bool refresh = on_trajectory && drift > kSampledDriftShare * kIdentityDriftShare * tolerance_;
  if (!refresh && on_trajectory) max_reused_drift_ = std::max(max_reused_drift_, drift);
  return refresh;
}

void IdentityTermCache::refresh(const double* diagonal, bool on_trajectory, bool sample_called) {
  if (!on_trajectory) return;
  // After a jump the older refresh lies on another surface: the line starts again from this one.
  const bool restart_line = jumped_;
  // A refresh the sample called measures, over all nodes, the drift of the reuse it replaced: how
  // far the sample's estimate falls short of the whole surface's. Forced refreshes (the first, a
  // corner jump, a verified surface) replace no reuse that the sample passed.
  const bool measure = sample_called && refresh_records_ > 0;
  const double s = extrapolation_, s2 = extrapolation2_;
  double drift = 0;
  // Per node, in the local frames of their refreshes: E1, C1 (the last refresh), E0 and E−1.
#pragma omp parallel for schedule(static) reduction(max : drift) num_threads(threads_)
  for (Eigen::Index i = 0; i < n_nodes_; ++i) {
    const size_t k = static_cast<size_t>(i);
    const Mat3 C = symmetric_matrix(&corner_[kCorner * k]), R = Eigen::Map<const Mat3>(&corner_[kCorner * k + 6]);
    double* record = &refreshed_[kRecord * k];
    const Mat3 D1 = 0.5 * Mat3::Identity() - symmetric_matrix(&diagonal[6 * k]);
    if (measure) drift = std::max(drift, (D1 - C - R * extrapolated_error(record, s, s2) * R.transpose()).norm());
    std::copy(record + 12, record + 18, record + 18);
    std::copy(record, record + 6, record + 12);
    store_symmetric(R.transpose() * (D1 - C) * R, record);
    std::copy(&corner_[kCorner * k + 15], &corner_[kCorner * k + 21], record + 6);
  }
  if (measure) {
    max_drift_ = std::max(max_drift_, drift);
    max_drift_over_sampled_ = std::max(max_drift_over_sampled_, drift / sampled_drift_);  // sampled_drift_ > 0 here
  }
  refresh_records_ = restart_line ? 1 : std::min(refresh_records_ + 1, 3);
  ++refreshes_;
}

void IdentityTermCache::reuse(double* diagonal) const {
  const double s = extrapolation_, s2 = extrapolation2_;
#pragma omp parallel for schedule(static) num_threads(threads_)
  for (Eigen::Index i = 0; i < n_nodes_; ++i) {
    const size_t k = static_cast<size_t>(i);
    const Mat3 C = symmetric_matrix(&corner_[kCorner * k]), R = Eigen::Map<const Mat3>(&corner_[kCorner * k + 6]);
    store_symmetric(0.5 * Mat3::Identity() - (C + R * extrapolated_error(&refreshed_[kRecord * k], s, s2) * R.transpose()),
                    &diagonal[6 * k]);
  }
}

IdentityTermStats IdentityTermCache::stats() const {
  IdentityTermStats st;
  st.refreshes = refreshes_;
  st.max_drift = max_drift_;
  st.max_drift_over_sampled = max_drift_over_sampled_;
  st.max_reused_drift = max_reused_drift_;
  st.sampled_drift = sampled_drift_;
  st.extrapolation = extrapolation_;
  st.samples = samples_;
  return st;
}

bool IdentityTermCache::set_records(const std::vector<double>& records, int count) {
  if (records.size() != refreshed_.size() || count < 0 || count > 3) return false;
  refreshed_ = records, refresh_records_ = count;
  return true;
}

}  // namespace capsflow
