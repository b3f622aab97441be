#pragma once
// The double layer's D̃[1] between refreshes (docs/boundary-integral.md §4.7.5). D̃[1](x_i), the
// discrete double layer of the three unit constants at node i (double_layer.hpp), is split into the
// polyhedron's exact corner value C_i (corner_double_layer.hpp: local, closed form) and the
// quadrature's error E_i = D̃[1](x_i) − C_i, which follows the surface slowly. A refresh (the
// operator's full far-field pass) stores E in each node's local frame R_i (columns: the tangent
// towards the first vertex of its fan, the binormal, the area-weighted outward normal), so that E
// turns with the surface; a set-up between refreshes reuses
//
//   D̃[1](x_i) = C_i + R_i E_i R_iᵀ,   E = E1 + s (E1 − E0) + s2 (E0 − E−1)
//
// with the current C and R, E extrapolated along the last two or three refreshes (E1 the last).
// s and s2 are fitted by least squares to a sample of nodes at which every set-up gives the exact
// D̃[1] (the double layer sums it directly there), and the reuse's largest error at the sample —
// the sampled drift — decides: a set-up on the trajectory refreshes when it exceeds
// kSampledDriftShare × kIdentityDriftShare × tolerance. Forced refreshes: none kept yet, a corner
// value that jumped between the samples, a surface whose far field is checked (verify_every).
//
// D̃[1] is read and written as the double layer holds it: its diagonal block ½ I − D̃[1](x_i), the
// 6 entries of a symmetric matrix (xx yy zz xy xz yz) per node.
#include <vector>

#include "capsflow/core/bie/corner_double_layer.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

// A symmetric 3×3 matrix from its 6 entries (xx yy zz xy xz yz), and stored as them (the
// off-diagonal entries averaged).
inline Mat3 symmetric_matrix(const double* b) {
  Mat3 m;
  m << b[0], b[3], b[4], b[3], b[1], b[5], b[4], b[5], b[2];
  return m;
}
inline void store_symmetric(const Mat3& m, double* b) {
  b[0] = m(0, 0), b[1] = m(1, 1), b[2] = m(2, 2), b[3] = 0.5 * (m(0, 1) + m(1, 0)), b[4] = 0.5 * (m(0, 2) + m(2, 0)),
  b[5] = 0.5 * (m(1, 2) + m(2, 1));
}

// What the cache reports (summary.json's viscosity_ratio.identity_term; tests).
struct IdentityTermStats {
  long refreshes = 0;      // trajectory set-ups that refreshed E by a full pass
  // The largest drift over all nodes that a refresh called by the sample measured (max of the
  // Frobenius norm of fresh − reused: what the reuse there would have erred by; forced refreshes
  // excluded), and its largest ratio to the sampled drift that called it (the sample's margin,
  // kSampledDriftShare, assumes it stays below 2).
  double max_drift = 0, max_drift_over_sampled = 0;
  double max_reused_drift = 0;  // the largest sampled drift of a trajectory set-up that reused
  // This set-up's: the sampled drift and s (0 on a forced refresh; a refresh the sample called
  // keeps the values that called it).
  double sampled_drift = 0, extrapolation = 0;
  std::vector<int> samples;  // the sample's nodes
};

class IdentityTermCache {
 public:
  // The drift a reuse may have, as a share of the tolerance (the FMM's own margin,
  // kFmmToleranceMargin): the allowance. A set-up refreshes when the sampled drift exceeds
  // kSampledDriftShare of it: the other half covers the nodes between the samples (the drift is
  // smooth over the surface: E follows the local geometry) and the refresh pass's own error, which
  // that pass keeps below kRefreshPassShare of the allowance (so that the extrapolation does not
  // amplify FMM noise much).
  static constexpr double kIdentityDriftShare = 0.25;
  static constexpr double kSampledDriftShare = 0.5;
  static constexpr double kRefreshPassShare = 0.25;
  // The sample: about this many nodes spread over the surface (every k-th of the given order); at
  // 81 920 elements their direct sums cost ~2 % of a λ = 5 evaluation.
  static constexpr int kSamples = 512;

  // The closed triangulation's vertex fans; the sample from node_order (breadth-first over the
  // mesh: consecutive nodes are neighbours, so every k-th spreads over the surface); tolerance:
  // the far field's (fluid.tolerance).
  IdentityTermCache(const Triangles& triangles, Eigen::Index n_nodes, const std::vector<int>& node_order, double tolerance,
                    int threads);

  const std::vector<int>& samples() const { return samples_; }
  // The largest error (max over nodes, relative to the density) the refresh pass may have.
  double refresh_pass_error() const { return kRefreshPassShare * kIdentityDriftShare * tolerance_; }

  // A new surface x: C_i and R_i at every node, the jump guard, and this set-up's fit cleared.
  void set_surface(const Points& x);
  // Whether this set-up must take the full pass whatever the sample says: no refresh kept yet, a
  // jump the sample cannot see, or (on the trajectory) a surface whose far field is checked.
  bool forced_refresh(bool on_trajectory, bool verify_now) const;
  // The exact D̃[1] at the samples (in samples() order): fits s and s2 there and measures the
  // reuse's drift. True when this set-up must refresh for it (on the trajectory only).
  bool measure(const std::vector<Mat3>& exact, bool on_trajectory);
  // A refresh: `diagonal` holds ½ I − D̃[1] of the full pass. On the trajectory its E is stored
  // (off it, the set-up takes the pass for itself only: storing would make the run depend on its
  // outputs); sample_called: the sample asked for it, whose all-node drift is then measured.
  void refresh(const double* diagonal, bool on_trajectory, bool sample_called);
  // A reuse: ½ I − (C + R E Rᵀ) into `diagonal`.
  void reuse(double* diagonal) const;

  IdentityTermStats stats() const;

  // The records (per node E1, C1, E0, E−1 in the local frames, 24 doubles) and how many refreshes
  // they hold: all that a set-up carries to the next, which a checkpoint keeps so that a restarted
  // run continues bit for bit. set_records puts them back; records of another size (another mesh)
  // or a count outside 0–3 are refused: false, nothing changed.
  const std::vector<double>& records() const { return refreshed_; }
  int record_count() const { return refresh_records_; }
  bool set_records(const std::vector<double>& records, int count);

 private:
  Mat3 local_frame(const Points& x, Eigen::Index i) const;
  double sampled_drift(double s, double s2) const;  // the reuse's largest at the sample (after measure's fit)

  Eigen::Index n_nodes_;
  double tolerance_;
  int threads_;
  CornerFans fans_;
  std::vector<double> refreshed_;  // per node: E1, C1 (the last refresh), E0, E−1 (the two before), local frames
  std::vector<double> corner_;     // per node on the current surface: C (6), the local frame R (9), C in it (6)
  int refresh_records_ = 0;        // how many of the three refreshes are kept
  bool jumped_ = false;            // a corner value jumped since the last refresh where the sample did not see it
  std::vector<int> samples_;       // the nodes at which every set-up measures the reuse's drift
  std::vector<Mat3> sample_error_; // E there in the local frames (measure's)
  double extrapolation_ = 0, extrapolation2_ = 0;  // s, s2 of this set-up's reuse
  double sampled_drift_ = 0;
  double max_drift_ = 0, max_drift_over_sampled_ = 0, max_reused_drift_ = 0;
  long refreshes_ = 0;
};

}  // namespace capsflow
