#include "capsflow/core/stepping/time_plan.hpp"

#include <algorithm>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "capsflow/core/stepping/auto_scheme.hpp"
#include "capsflow/core/stepping/auto_tolerance.hpp"
#include "capsflow/core/stepping/stability.hpp"

namespace capsflow {

namespace {

// The scheme and why.
void choose_scheme(const Scene& scene, TimePlan& p) {
  p.chosen_by_auto = scene.time.scheme == TimeScheme::Auto;
  if (!p.chosen_by_auto) {
    p.scheme = scene.time.scheme;
    p.reason = "as the scene names it";
  } else if (!scene.time.dt_auto) {
    p.scheme = TimeScheme::Rkc;
    p.reason = "auto with a fixed time.dt: RKC2, whose stages follow the stiffness at that step";
  } else {
    p.scheme = auto_scheme(p.stiffness);
    const bool rock4 = p.scheme == TimeScheme::Rock4;
    p.reason = fmt::format("auto: the analytic spectral radius {:.0f} is {} {:g}: {}", p.stiffness,
                           rock4 ? "below" : "not below", kAutoSchemeRock4BelowStiffness,
                           rock4 ? "fourth order pays where accuracy sets the step"
                                 : "RKC2's longer stability interval pays where stability does");
  }
}

// The tolerance the run starts with and what happens at the creases.
void choose_tolerance(const Scene& scene, long elements, TimePlan& p) {
  p.error_control = is_stabilized(p.scheme) && scene.time.dt_auto;
  if (!p.error_control) return;
  p.tolerance_auto = scene.time.tolerance_auto;
  if (!p.tolerance_auto) {
    p.tolerance = scene.time.tolerance;
    return;
  }
  if (p.scheme == TimeScheme::Rock4) {
    p.tolerance = auto_tolerance_rock4(elements, scene.wall.model == WallModel::Membrane);
    p.at_creases = CreaseAction::Loosen;
    p.crease_tolerance = auto_tolerance_rock4_past_creases(p.tolerance);
    p.reason += fmt::format("; tolerance {:g} for {} elements, {:g} once the wall creases", p.tolerance, elements,
                            p.crease_tolerance);
  } else {
    p.tolerance = kAutoToleranceLoose;
    p.at_creases = CreaseAction::Rewind;
    p.crease_tolerance = kAutoToleranceFolded;
    p.reason += fmt::format("; tolerance {:g}, and if the wall creases the run starts again from t = 0 at {:g} up to the "
                            "creases", p.tolerance, p.crease_tolerance);
  }
}

}  // namespace

TimePlan resolve_time_plan(const Scene& scene, const SurfaceMesh& reference) {
  TimePlan p;
  p.stiffness = analytic_spectral_radius(scene, min_edge_length(reference));
  choose_scheme(scene, p);
  choose_tolerance(scene, static_cast<long>(reference.num_elements()), p);
  return p;
}

int stiffest_capsule(const Scene& scene, const SurfaceSet& capsules) {
  if (capsules.size() == 1 || scene.capsules_alike()) return 0;  // alike: the same radius for all
  int stiffest = 0;
  double rho = -1;
  for (int k = 0; k < capsules.size(); ++k) {
    const double r = analytic_spectral_radius(scene.capsule_scene(k),
                                              min_edge_length(capsules.part_mesh(capsules.mesh().vertices, k)));
    if (r > rho) {
      rho = r;
      stiffest = k;
    }
  }
  return stiffest;
}

TimePlan resolve_time_plan(const Scene& scene, const SurfaceSet& capsules) {
  const Points& x = capsules.mesh().vertices;
  const int stiffest = stiffest_capsule(scene, capsules);
  TimePlan plan = resolve_time_plan(scene.capsule_scene(stiffest), capsules.part_mesh(x, stiffest));
  if (scene.capsules_alike() || !plan.tolerance_auto) return plan;
  for (int k = 0; k < capsules.size(); ++k) {
    Scene own = scene.capsule_scene(k);
    own.time.scheme = plan.scheme;  // its tolerance under the scheme the run takes
    const TimePlan p = resolve_time_plan(own, capsules.part_mesh(x, k));
    plan.tolerance = std::min(plan.tolerance, p.tolerance);
    plan.crease_tolerance = std::min(plan.crease_tolerance, p.crease_tolerance);
  }
  return plan;
}

double TimePlan::tolerance_in_force(const CreaseHistory& h, double t) const {
  switch (at_creases) {
    case CreaseAction::Loosen: return h.seen_at ? crease_tolerance : tolerance;
    case CreaseAction::Rewind: return h.tightened && !(h.tight_until && t >= *h.tight_until) ? crease_tolerance : tolerance;
    case CreaseAction::None: break;
  }
  return tolerance;
}

bool restart_keeps_time_plan(const Scene& stored, const Scene& next) {
  const TimeSpec &a = stored.time, &b = next.time;
  return a.scheme == b.scheme && a.tolerance_auto == b.tolerance_auto && (a.tolerance_auto || a.tolerance == b.tolerance) &&
         a.dt_auto == b.dt_auto && (a.dt_auto || a.dt == b.dt);
}

nlohmann::json TimePlan::to_json() const {
  return {{"scheme", to_string(scheme)},          {"chosen_by_auto", chosen_by_auto},
          {"error_control", error_control},       {"tolerance_auto", tolerance_auto},
          {"tolerance", tolerance},               {"at_creases", to_string(at_creases)},
          {"crease_tolerance", crease_tolerance}, {"stiffness", stiffness},
          {"reason", reason}};
}

TimePlan TimePlan::from_json(const nlohmann::json& j) {
  TimePlan p;
  const auto scheme = from_string<TimeScheme>(j.at("scheme").get<std::string>());
  const auto action = from_string<CreaseAction>(j.at("at_creases").get<std::string>());
  if (!scheme || *scheme == TimeScheme::Auto || !action)
    throw std::runtime_error("time plan: unknown scheme or crease action " + j.dump());
  p.scheme = *scheme;
  p.at_creases = *action;
  p.chosen_by_auto = j.at("chosen_by_auto");
  p.error_control = j.at("error_control");
  p.tolerance_auto = j.at("tolerance_auto");
  p.tolerance = j.at("tolerance");
  p.crease_tolerance = j.at("crease_tolerance");
  p.stiffness = j.at("stiffness");
  p.reason = j.at("reason");
  return p;
}

}  // namespace capsflow
