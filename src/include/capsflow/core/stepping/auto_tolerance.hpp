#pragma once
// time.tolerance = "auto" (docs/time-integration.md §5.3): RKC runs at a loose tolerance, and a run
// whose wall creases at the mesh scale starts again from t = 0 at a tight one, which it keeps up to
// the time where the creases were seen and then leaves for the loose one again (the driver's
// rewind, src/driver/rewind.cpp). ROCK4's "auto" (below) follows the mesh from t = 0 instead and
// loosens where the run sees the creases, without a rewind.
//
// Why a rewind and not a switch: where the wall folds at the mesh scale, the D_ij error present
// when the folds form is amplified 4–6× while they form (§5.6, Table 1 α = 3 %), so the error that
// matters is made before the folds are seen; tightening at detection measured 6.8e-4 where the
// tight tolerance from the start gives 8.7e-5.
//
// Why loose again past the creases: once they have formed, the error made is no longer amplified.
// Table 1 α = 3 % at 1 280 elements: 1e-5 throughout leaves 2.1e-4, 1e-6 throughout 5.7e-5; 1e-6
// up to γ̇t = 0.9 or 1.3 and 1e-5 after, 4.6e-5 and 5.1e-5; but 1e-5 up to 0.8 and 1e-7 after,
// 2.1e-4 again (§5.3).
#include <algorithm>
#include <cmath>

namespace capsflow {

// Smooth walls: 1e-5 keeps D_ij within 5.3e-5 of the quarter-step reference on every paper case
// that does not fold at its mesh (Table 1 α = 10 % at 1 280 and 5 120 elements, a/b = 4 at 1 280),
// and within 5.2e-5 on Fig. 4 and a/b = 4 at 5 120 elements, which do (§5.6 tables).
inline constexpr double kAutoToleranceLoose = 1e-5;
// ... where the folds are creases: neighbouring facet normals more than this apart. Folds alone
// (the monitors' grid-scale criterion) do not decide it: Fig. 4 and a/b = 4 at 5 120 elements
// and the built-in scene fold (facet angles up to 60°, 69° and 54°) and keep 5.0e-5, 5.2e-5 and
// 3.5e-5 at the loose tolerance, where Table 1 α = 3 % (90° at 5 120 elements, 92° at 1 280) and
// the NH membrane (130°, 99°) give 1.7e-4 to 3.9e-4 (§5.6). 80° lies between the two groups; it
// is calibrated on those eleven case-and-mesh pairs, not derived.
inline constexpr double kAutoToleranceCreaseDeg = 80.0;
// Folding walls, from t = 0 up to the creases: half the former uniform default 1e-6, which on the
// worst case (Table 1 α = 3 % at 5 120 elements, §5.3) leaves 1.0e-4 and, loosened past the
// creases, 1.2e-4; 5e-7 then 1e-5 keeps 9.0e-5 with fewer evaluations than 1e-6 throughout.
inline constexpr double kAutoToleranceFolded = 5e-7;

// ROCK4 (time.scheme = "rock4", docs/time-integration.md §5.8, §5.4): one tolerance per mesh from
// t = 0 up to the creases, no rewind. It bounds the grid-scale-filtered estimate of the embedded
// third-order solution, so the fourth-order solution the run keeps is more accurate than the number
// says. It falls like the element area, 1/N: where the wall creases at the mesh scale the error
// that matters is made at that scale, and the space discretisation's own error falls about like
// h² ∝ 1/N (perf/RESULTS.md §2.5: observed orders 1.3–2.3), so the time error stays the same
// fraction of it. At one value for every mesh, Table 1 α = 3 % needed ≥ 2e-3 at 1 280 elements
// (1e-3: 4.9× fewer evaluations than Heun) and ≤ 1e-3 at 5 120 (2e-3: D_ij off by 1.4e-4), §5.8.
inline constexpr double kAutoToleranceRock4At1280 = 2e-3;
// A plain membrane has no bending length to bound the wavenumber of its buckles: they form at the
// mesh scale and grow faster on a finer mesh (the grid-scale oscillation of the NH membrane's
// reference runs grew 3.3× in 0.1 of γ̇t at 1 280 elements, 11× at 5 120), so the error made before
// them is amplified more and its tolerance must fall faster: like N^(-8/3), 2e-3 at 1 280 elements
// and 5e-5 at 5 120 (§5.4: 1.25e-4 up to the creases left 1.2e-4 in D_ij there, 5e-5 6.0e-5).
// Calibrated on the two meshes, not derived.
inline constexpr double kAutoToleranceRock4MembraneExponent = 8.0 / 3.0;
inline double auto_tolerance_rock4(long elements, bool plain_membrane) {
  const double coarsening = elements > 0 ? 1280.0 / static_cast<double>(elements) : 1.0;
  return kAutoToleranceRock4At1280 * (plain_membrane ? std::pow(coarsening, kAutoToleranceRock4MembraneExponent) : coarsening);
}
// Past the creases (the crease criterion above, seen in the run itself): 2e-3, or the tolerance
// before them where that is looser (coarser than 1 280 elements). As for RKC2 (§5.3), once the
// creases have formed the error made is no longer amplified: NH membrane at 5 120 elements, 5e-5
// up to the creases and 2e-3 after, 823 evaluations and 6.2e-5, against 941 and 6.0e-5 with 5e-4
// after; Table 1 α = 3 %, 5e-4 then 2e-3: 777 evaluations and 5.6e-5, against 896 and 5.5e-5 (§5.4).
inline double auto_tolerance_rock4_past_creases(double before_creases) {
  return std::max(kAutoToleranceRock4At1280, before_creases);
}

}  // namespace capsflow
