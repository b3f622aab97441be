#pragma once
// Health of a time step: what makes a run stop as "blow_up" (docs/time-integration.md §5.10).
#include <string>

#include "capsflow/core/types.hpp"

namespace capsflow {

// Early detection of a failing run (docs/time-integration.md §5.10): non-finite positions, an
// element whose normal flipped during the step (inversion), a collapsed element, or runaway
// volume. Returns an empty string when healthy, otherwise a one-line description.
// A stable step changes an element's area by a factor 1 + O(|∇v|Δt), a few percent at most, so
// an area ratio below kCollapsedAreaRatio in one step is a collapse, not deformation. The volume
// correction keeps the drift of a healthy run near 1e-8 (quick.toml to γ̇t = 2: 7e-9), so 5 %
// is far beyond any physical state: it is the last-resort "runaway" check.
inline constexpr double kCollapsedAreaRatio = 1e-6;
// The volume drift beyond which a step is a blow-up. With the volume correction a healthy run
// drifts by 1e-8 (Heun) or 1e-14 (RKC): 1e-3 is an instability under way. Without it the drift is
// physical-numerical and only the runaway above counts.
inline double blow_up_drift(bool volume_correction) { return volume_correction ? 1e-3 : 0.05; }
// volume_drift is V(after)/V0 − 1, computed by the caller (which also feeds it to InstabilityWatch).
std::string check_health(const SurfaceMesh& before, const Points& after, double volume_drift, double max_volume_drift);

}  // namespace capsflow
