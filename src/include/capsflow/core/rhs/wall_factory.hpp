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
// The stress-free nodes of a wall pre-inflated by 1 + prestress: the initial ones shrunk by that
// factor about the initial volume centroid (the initial nodes themselves at prestress 0).
Points stress_free_nodes(const SurfaceMesh& initial, double prestress);
// The scene's in-plane law with G_s = 1/Ca_s (the membrane of either wall model).
shell::MembraneLaw scene_law(const Scene& scene);

}  // namespace capsflow
