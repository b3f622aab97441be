#include "capsflow/core/stepping/auto_scheme.hpp"

#include <fmt/core.h>

#include "capsflow/core/scene/scene.hpp"
#include "capsflow/core/stepping/stability.hpp"

namespace capsflow {

std::string auto_scheme_reason(double rho) {
  return fmt::format("the analytic spectral radius {:.0f} is {} {:g}", rho,
                     auto_scheme(rho) == TimeScheme::Rock4 ? "below" : "not below", kAutoSchemeRock4BelowStiffness);
}

void resolve_auto_scheme(Scene& scene, double min_edge) {
  if (!scene.time.scheme_auto) return;
  scene.time.scheme_for_mesh = true;
  if (scene.time.dt_auto) scene.time.scheme = auto_scheme(analytic_spectral_radius(scene, min_edge));
}

}  // namespace capsflow
