#pragma once
// The capsule wall of a scene: a membrane (explicit forces) or a GSMB shell (rotation solve),
// with the scene's law and moduli in the project's units (docs/conventions.md §1), whose
// stress-free shape is the capsule's initial one, or that shape shrunk by 1 + α_p for a
// pre-inflated wall (wall.prestress, docs/shell.md §2.10).
#include <memory>

#include "capsflow/core/scene/scene.hpp"
#include "capsflow/shell/wall.hpp"

namespace capsflow {

// initial: the capsule's mesh at t = 0.
std::unique_ptr<shell::Wall> make_wall(const Scene& scene, const SurfaceMesh& initial);
// The stress-free nodes of a wall pre-inflated by 1 + prestress and started stretched along x1 by
// `stretch` (wall.initial_stretch): the initial ones shrunk by 1 + prestress, compressed along x1
// by the stretch and widened across by its square root, about the initial volume centroid (the
// initial nodes themselves at prestress 0 and stretch 1).
Points stress_free_nodes(const SurfaceMesh& initial, double prestress, double stretch = 1);
// The inverse map of the stretch: the capsule's initial nodes from its mesh's (about the mesh's
// volume centroid; the mesh's own nodes at stretch 1).
Points stretched_nodes(const SurfaceMesh& mesh, double stretch);
// The scene's in-plane law with G_s = 1/Ca_s (the membrane of either wall model).
shell::MembraneLaw scene_law(const Scene& scene);

}  // namespace capsflow
