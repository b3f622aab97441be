#pragma once
// Where a run's capsules start (docs/several-capsules.md): each capsule's mesh (its own [mesh] keys,
// or the scene's) moved to its centre (Scene::capsule_centers), as one union
// (geometry/surface_set.hpp). One capsule at the origin is its mesh as it is, bit for bit.
#include "capsflow/core/geometry/surface_set.hpp"
#include "capsflow/core/rhs/channel_dynamics.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

SurfaceSet place_capsules(const Scene& scene);

// Refuses (SceneError, one line naming the capsules and the key to change) capsules
// that overlap where they start: a node of one behind (or on) the nearest element of another. Every
// mesh has the volume of the unit sphere (ℓ = 1), so no capsule lies inside another without one.
void check_capsules_apart(const Scene& scene, const SurfaceSet& capsules);

// The channel of a scene with one (docs/channel.md §4) around `capsule` where it starts: the wall's
// element size resolved ("auto": the capsule's mean edge, but not finer than radius/8), and refused
// (SceneError naming the channel key) when the capsule does not fit inside its cross-section (less
// than a tenth of a wall element from the wall), the channel is shorter than the capsule plus 4 radii, or
// the wall's elements are more than 4 times the capsule's mean edge.
ChannelFlow channel_flow_of(const Scene& scene, const SurfaceMesh& capsule);

}  // namespace capsflow
