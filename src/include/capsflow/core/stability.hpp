#pragma once
// Explicit time-step limit of the coupled capsule problem (numerics.md §5.1): von Neumann
// analysis of RK2 on a locally flat wall with the highest mesh mode k = π/Δx:
//   membrane  γ̇Δt ≤ c_m · G_s/(K_s + G_s) · Ca_s · Δx/ℓ          (paper Eq. 41), c_m = 8/π
//   bending   γ̇Δt ≤ c_b · (G_s ℓ²/B) · Ca_s · (Δx/ℓ)³,  B/(G_s ℓ²) = α²/(6(1 − ν)), c_b = 8/π³
// plus an accuracy cap for the flow itself (|L|Δt ≤ kFlowCap). dt = "auto" takes
// safety × the smallest of these, recomputed every step from the current shortest edge.
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

inline constexpr double kFlowCap = 0.02;

// K_s/G_s at small strain for the scene's law.
double area_to_shear_modulus_ratio(const Scene& scene);
StabilityEstimate stability_estimate(const Scene& scene, double min_edge);

}  // namespace capsflow
