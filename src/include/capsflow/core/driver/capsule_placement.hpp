#pragma once
// Where a run's capsules start (docs/several-capsules.md): each capsule's mesh (its own [mesh] keys,
// or the scene's) moved to its centre (Scene::capsule_centers), as one union
// (geometry/surface_set.hpp). One capsule at the origin is its mesh as it is, bit for bit.
#include "capsflow/core/geometry/surface_set.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

SurfaceSet place_capsules(const Scene& scene);

// Refuses (SceneError, one line naming the capsules and the key to change) capsules
// that overlap where they start: a node of one behind (or on) the nearest element of another. Every
// mesh has the volume of the unit sphere (ℓ = 1), so no capsule lies inside another without one.
void check_capsules_apart(const Scene& scene, const SurfaceSet& capsules);

}  // namespace capsflow
