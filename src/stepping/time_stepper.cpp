#include "capsflow/core/stepping/time_stepper.hpp"

#include <spdlog/spdlog.h>

#include <memory>

#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/rhs/volume_constraint.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "capsflow/core/stepping/grid_scale_filter.hpp"
#include "capsflow/core/stepping/heun.hpp"
#include "capsflow/core/stepping/rkc.hpp"
#include "capsflow/core/stepping/stability.hpp"

namespace capsflow {

namespace {

// The calibrated stable Heun step at a state (stability.hpp), from its shortest edge.
std::function<double(const Points&)> stable_step(const Scene& scene, const Triangles& triangles) {
  return [scene, triangles](const Points& x) {
    return stability_estimate(scene, min_edge_length(SurfaceMesh{x, triangles})).limit();
  };
}

std::unique_ptr<TimeStepper> make_heun(const Scene& scene, const Triangles& triangles, const Points& x) {
  Heun::Options o;
  o.dt_auto = scene.time.dt_auto;
  o.dt = scene.time.dt;
  o.safety = scene.time.dt_safety;
  o.stable_step = stable_step(scene, triangles);
  if (!o.dt_auto) {
    const double limit = o.stable_step(x);
    if (o.dt > limit)
      spdlog::warn("time.dt = {:g} is {:.2g}× the stability estimate {:.3g} of this mesh and wall: Heun is expected to blow up "
                   "(use dt = \"auto\", or time.scheme = \"rkc\", whose stages follow the stiffness)",
                   o.dt, o.dt / limit, limit);
  }
  return std::make_unique<Heun>(std::move(o));
}

std::unique_ptr<TimeStepper> make_rkc(const Scene& scene, const Triangles& triangles, double volume0) {
  Rkc::Options o;
  o.method = scene.time.scheme == TimeScheme::Rock4 ? Rkc::Method::Rock4 : Rkc::Method::Rkc2;
  o.tolerance = scene.time.tolerance;
  o.error_control = scene.time.dt_auto;
  o.fixed_dt = scene.time.dt_auto ? 0.0 : scene.time.dt;
  // The calibrated Heun limit gives the analytic bound used when the power iteration does not converge.
  o.analytic_rho = [scene, triangles](const Points& y) {
    return analytic_spectral_radius(scene, min_edge_length(SurfaceMesh{y, triangles}));
  };
  // RKC's large steps add O(τ³) volume error per step that the velocity-level correction cannot
  // see: project each new state back onto the initial volume.
  if (scene.fluid.volume_correction)
    o.project = [triangles, volume0, scratch = Points()](Points& y) mutable { project_volume(y, triangles, volume0, scratch); };
  if (o.method == Rkc::Method::Rock4) {
    auto filter = std::make_shared<GridScaleFilter>(triangles, kRock4ErrorFilterPasses);
    o.filter_error = [filter](Points& estimate) { filter->apply(estimate); };
  }
  return std::make_unique<Rkc>(std::move(o));
}

}  // namespace

std::unique_ptr<TimeStepper> make_time_stepper(const Scene& scene, const Triangles& triangles, double volume0,
                                               const Points& x) {
  switch (scene.time.scheme) {
    case TimeScheme::Rkc:
    case TimeScheme::Rock4: return make_rkc(scene, triangles, volume0);
    case TimeScheme::Heun: return make_heun(scene, triangles, x);
    case TimeScheme::Auto: break;  // resolved when the scene is read
  }
  throw std::logic_error("make_time_stepper: the scene's time scheme was not resolved");
}

}  // namespace capsflow
