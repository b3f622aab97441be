#pragma once
// A low-pass filter over the wall's nodes for ROCK4's error estimate (docs/time-integration.md
// §5.8): v ← (I + U/2)^passes v, U the umbrella operator. A mode of U with eigenvalue λ ∈ [−2, 0]
// is multiplied by (1 + λ/2)^passes: constants pass unchanged, smooth fields nearly so, and the
// two-element-wavelength modes (λ ≈ −2) — the stiff ones — are removed.
//
// Why: on a stiff mode z = τλ_J the embedded estimate of ROCK4 grows like |z| (b̂5 ≈ 2.09), and
// ROCK4 damps those modes little (|R| ≈ 0.93), so the estimate measured the stiff residue rather
// than the error of the motion and the controller shortened accurate steps (§5.8). RKC2 damps
// them (its estimate filtered the same way changes its counts by 1–3 %), so only ROCK4 is filtered.
#include "capsflow/core/geometry/umbrella.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

// Measured at 1 280 elements, tolerance 1e-3 (§5.8), evaluations on Table 1 α = 3 %, the NH
// membrane, Fig. 4: one pass 617, 473, 847; two 519, 476, 731; three 454, 476, 698. Three are
// cheaper still but hide more than the stiff modes: the membrane's D_ij error rose from 4.2e-5 to
// 5.9e-5 and the L_i error of a/b = 4 from 3.6e-5 to 2.4e-4. Two passes.
inline constexpr int kRock4ErrorFilterPasses = 2;

class GridScaleFilter {
 public:
  GridScaleFilter(const Triangles& triangles, int passes);
  int passes() const { return passes_; }
  void apply(Points& v);  // in place; v is one row per node

 private:
  UmbrellaOperator umbrella_;
  int passes_;
  Points u_;  // U v, reused between calls
};

}  // namespace capsflow
