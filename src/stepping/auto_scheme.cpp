#include "capsflow/core/stepping/auto_scheme.hpp"

#include "capsflow/core/scene/scene.hpp"
#include "capsflow/core/stepping/stability.hpp"

namespace capsflow {

void resolve_auto_scheme(Scene& scene, double min_edge) {
  if (!scene.time.scheme_auto) return;
  scene.time.scheme_for_mesh = true;
  if (scene.time.dt_auto) scene.time.scheme = auto_scheme(analytic_spectral_radius(scene, min_edge));
}

}  // namespace capsflow
