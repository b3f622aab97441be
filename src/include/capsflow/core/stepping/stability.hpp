#pragma once
// Explicit time-step limit of the coupled capsule problem (docs/time-integration.md §5.9): von Neumann
// analysis of RK2 on a locally flat wall with the highest mesh mode k = π/Δx:
//   membrane  γ̇Δt ≤ c_m · G_s/(K_s + G_s) · Ca_s · Δx/ℓ          (paper Eq. 41)
//   bending   γ̇Δt ≤ c_b · (G_s ℓ²/B) · Ca_s · (Δx/ℓ)³,  B/(G_s ℓ²) = α²/(6(1 − ν)), c_b = 8/π³
// plus an accuracy cap for the flow itself (|L|Δt ≤ kFlowCap). dt = "auto" takes
// safety × the smallest of these, recomputed every step from the current shortest edge.
// The theory gives c_m = 8/π ≈ 2.55 and c_b = 8/π³; c_m is calibrated by bisection of the fixed
// dt at which runs blow up (perf/stability/bisect_dt.sh; table in perf/RESULTS.md §3.1): GH, Ca_s = 0.1, levels 2 and
// 3 → c_m = 1.41 and 1.45 (NH: 1.94, Skalak C = 1: 1.65); kMembraneConstant = 1.4 is the
// conservative value. A thick GSMB wall (α = 0.3, level 3) is stable up to the membrane limit,
// 3× above the theoretical bending limit, so c_b ≥ 0.74: kBendingConstant = 0.7.
#include <cmath>
#include <string>

namespace capsflow {

struct Scene;

struct StabilityEstimate {
  double membrane = 0;  // γ̇Δt limit from membrane stiffness
  double bending = 0;   // from bending stiffness (infinite for a membrane wall)
  double flow = 0;      // accuracy cap from the imposed flow
  double limit() const;
  std::string limiting() const;  // "membrane" | "bending" | "flow"
};

// Heun's relative error per unit time in a linear flow is (|L|Δt)²/6: 7e-5 at |L|Δt = 0.02, below
// the 1e-4 to which D_ij are reported. Limits only soft walls (large Ca_s) on coarse meshes.
inline constexpr double kFlowCap = 0.02;
inline constexpr double kMembraneConstant = 1.4;  // calibrated: the smallest measured c_m, 1.41 (theory 8/π)
inline constexpr double kBendingConstant = 0.7;   // measured lower bound 0.74, rounded down (theory 8/π³)

// K_s/G_s at small strain for the scene's law.
double area_to_shear_modulus_ratio(const Scene& scene);
StabilityEstimate stability_estimate(const Scene& scene, double min_edge);
// The spectral radius that limit implies: Heun's real stability interval is 2.
double analytic_spectral_radius(const Scene& scene, double min_edge);

}  // namespace capsflow
