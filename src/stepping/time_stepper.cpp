#include "capsflow/core/stepping/time_stepper.hpp"

#include <spdlog/spdlog.h>

#include <memory>

#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/rhs/volume_constraint.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "capsflow/core/stepping/grid_scale_filter.hpp"
#include "capsflow/core/stepping/heun.hpp"
#include "capsflow/core/stepping/rkc2.hpp"
#include "capsflow/core/stepping/rock4.hpp"
#include "capsflow/core/stepping/stability.hpp"
#include "capsflow/core/stepping/time_plan.hpp"

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

StabilizedStepper::Options stabilized_options(const Scene& scene, const TimePlan& plan, double tolerance,
                                              const Triangles& triangles, double volume0) {
  StabilizedStepper::Options o;
  o.tolerance = tolerance;
  o.error_control = plan.error_control;
  o.fixed_dt = plan.error_control ? 0.0 : scene.time.dt;
  // The calibrated Heun limit gives the analytic bound used when the power iteration does not converge.
  o.analytic_rho = [scene, triangles](const Points& y) {
    return analytic_spectral_radius(scene, min_edge_length(SurfaceMesh{y, triangles}));
  };
  // The large steps add O(τ³) volume error per step that the velocity-level correction cannot
  // see: project each new state back onto the initial volume.
  if (scene.fluid.volume_correction)
    o.project = [triangles, volume0, scratch = Points()](Points& y) mutable { project_volume(y, triangles, volume0, scratch); };
  return o;
}

std::unique_ptr<TimeStepper> make_rock4(StabilizedStepper::Options o, const Triangles& triangles) {
  auto filter = std::make_shared<GridScaleFilter>(triangles, kRock4ErrorFilterPasses);
  o.filter_error = [filter](Points& estimate) { filter->apply(estimate); };
  return std::make_unique<Rock4>(std::move(o));
}

}  // namespace

std::unique_ptr<TimeStepper> make_time_stepper(const Scene& scene, const TimePlan& plan, double tolerance,
                                               const Triangles& triangles, double volume0, const Points& x) {
  switch (plan.scheme) {
    case TimeScheme::Rkc: return std::make_unique<Rkc2>(stabilized_options(scene, plan, tolerance, triangles, volume0));
    case TimeScheme::Rock4: return make_rock4(stabilized_options(scene, plan, tolerance, triangles, volume0), triangles);
    case TimeScheme::Heun: return make_heun(scene, triangles, x);
    case TimeScheme::Auto: break;  // the plan never holds it
  }
  throw std::logic_error("make_time_stepper: the time plan holds no scheme");
}

std::unique_ptr<TimeStepper> make_time_stepper(const Scene& scene, const TimePlan& plan, double tolerance,
                                               const SurfaceSet& capsules, std::vector<double> volumes0, const Points& x) {
  const Triangles& triangles = capsules.mesh().triangles;
  if (plan.scheme == TimeScheme::Heun) return make_heun(scene, triangles, x);  // Heun does not project
  StabilizedStepper::Options o = stabilized_options(scene, plan, tolerance, triangles, 0.0);
  if (scene.fluid.volume_correction)
    o.project = [projection = std::make_shared<VolumeProjection>(capsules, std::move(volumes0))](Points& y) {
      projection->apply(y);
    };
  switch (plan.scheme) {
    case TimeScheme::Rkc: return std::make_unique<Rkc2>(std::move(o));
    case TimeScheme::Rock4: return make_rock4(std::move(o), triangles);
    default: break;
  }
  throw std::logic_error("make_time_stepper: the time plan holds no scheme");
}

}  // namespace capsflow
