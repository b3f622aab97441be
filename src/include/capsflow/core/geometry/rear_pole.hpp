#pragma once
// The curvature of a capsule's rear on the x1 axis (docs/channel.md §5): in a channel a capsule
// carried along +x1 turns its rear from convex to concave — the parachute — as the flow grows.
// The rear pole is the node of the rear half (x1 below the centroid) nearest to the axis through
// the centroid; around it, the surface is fitted as x1 − x1_p = a + b Δx2 + c Δx3 + (κ/2)(Δx2² + Δx3²)
// by least squares over the nodes of the rear half within 2.5 mean edges of it across the axis.
// κ > 0: the rear bulges backwards (1/radius on a sphere); κ < 0: it is hollow (a parachute).
#include "capsflow/core/types.hpp"

namespace capsflow {

// NaN when fewer than 6 nodes are near the pole.
double rear_pole_curvature(const Points& x, const Triangles& triangles);

}  // namespace capsflow
