#pragma once
// time.scheme = "auto" with dt = "auto" (docs/time-integration.md §5.2): ROCK4 where the wall is
// soft for its mesh, RKC2 where it is stiff. The stiffness is the analytic spectral radius at the
// reference shape (stability.hpp: 2 over the calibrated Heun limit), in units of the flow rate:
// known before any evaluation, the same for `capsflow info` and the run. The time plan applies it
// (time_plan.hpp) and checkpoints keep the plan, so a continued run keeps its scheme.
//
// Why two schemes: where ρ is small a step spans few stages and accuracy sets the step, so the
// fourth order pays; on walls that crease at the mesh scale ROCK4 is the only one of the two that
// keeps D_ij within 1e-4 of the reference with 5× fewer evaluations than Heun (Table 1 α = 3 % and
// the NH membrane at 1 280 and 5 120 elements, §5.4). Where ρ is large, stability sets the stages,
// and RKC2's cover about 1.86× more of τρ per stage² (0.65 s² against ROCK4's 0.35 s²).
// ROCK4/RKC2 evaluation ratios at "auto" tolerances against this stiffness (§5.2): 0.51–0.87 at
// 307 (Table 1, 1 280 elements), 0.81–1.02 at 461 (built-in, Fig. 4), 0.65–1.11 at 616 (Table 1,
// 5 120), 0.80 at 654 (a/b = 4), 1.02–1.27 at 923 (built-in, Fig. 4 at 5 120), 1.09 at 1 232 (NH
// membrane, 20 480), 1.23 at 1 310 (a/b = 4, 5 120), 1.64 at 1 847 (Fig. 4, 20 480), 1.97 at
// 3 695 (81 920), 2.57 at 9 233 (NH membrane at Ca_s = 0.01, 5 120). The threshold lies between
// 616, where ROCK4 must run, and 923, where RKC2 is the cheaper: calibrated, not derived.
#include "capsflow/core/stepping/time_scheme.hpp"

namespace capsflow {

inline constexpr double kAutoSchemeRock4BelowStiffness = 800.0;

inline TimeScheme auto_scheme(double analytic_spectral_radius) {
  return analytic_spectral_radius < kAutoSchemeRock4BelowStiffness ? TimeScheme::Rock4 : TimeScheme::Rkc;
}

}  // namespace capsflow
