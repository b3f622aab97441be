#pragma once
// The capsule wall of a scene: a membrane (explicit forces) or a GSMB shell (rotation solve),
// with the scene's law and moduli in the project's units (docs/conventions.md §1).
#include <memory>

#include "capsflow/core/scene/scene.hpp"
#include "capsflow/shell/wall.hpp"

namespace capsflow {

std::unique_ptr<shell::Wall> make_wall(const Scene& scene, const SurfaceMesh& reference);
// The scene's in-plane law with G_s = 1/Ca_s (the membrane of either wall model).
shell::MembraneLaw scene_law(const Scene& scene);

}  // namespace capsflow
