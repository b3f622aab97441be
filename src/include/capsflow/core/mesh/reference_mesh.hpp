#pragma once
// Turning a resolved scene into the objects of a run (reference mesh first; walls, flows and the
// boundary-integral operator are built by the run itself).
#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

// The reference (initial) capsule surface of a scene: generated (sphere, spheroid or biconcave disc with ℓ = 1)
// or read from mesh.file (validated, oriented outward, rescaled to ℓ = 1, centred at the
// volume centroid).
SurfaceMesh make_reference_mesh(const MeshSpec& spec);

}  // namespace capsflow
