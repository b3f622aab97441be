#pragma once
// Spectral radius of the Jacobian of the right-hand side, by a nonlinear power iteration on
// right-hand-side differences (the approach of RKC, Sommeijer, Shampine & Verwer 1998):
//   w ← F(y + δ ŵ) − F(y),   σ = |w| / δ,   until σ changes by less than `rel_tol`,
// with δ = √ε |y| so that the difference quotient sees the linearisation. Warm-started from the
// last direction, so a refresh costs a few evaluations. The capsule problem's Jacobian −S K has
// real non-positive eigenvalues up to the O(γ̇) flow terms (docs/time-integration.md §5.6), so the
// dominant mode is the stiffest elastic mode and the iteration converges to it.
#include "capsflow/core/rhs/right_hand_side.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

// The power iteration converges from below: schemes use ρ = kSpectralRadiusMargin × σ.
inline constexpr double kSpectralRadiusMargin = 1.2;

class SpectralRadiusEstimator {
 public:
  struct Result {
    double sigma = 0;      // |λ_max| estimate (no safety margin)
    int evaluations = 0;
    bool converged = false;
  };
  // fy = F(y) must be given. max_iter bounds the evaluations (hinted as probes).
  Result estimate(RightHandSide& f, const Points& y, const Points& fy, int max_iter = 50, double rel_tol = 0.01);
  const Points& direction() const { return dir_; }
  void set_direction(const Points& d) { dir_ = d; }

 private:
  Points dir_, yv_, fv_;  // last direction; scratch
};

}  // namespace capsflow
