#pragma once
// How a run is stepped, decided once from the scene as the user wrote it and the reference mesh
// (docs/time-integration.md §5.2): the scheme, whether its step is error-controlled, the tolerance
// it starts with, what happens where the wall creases at the mesh scale, and the sentence saying
// why. `capsflow run`, `capsflow info`, studies and the Python module call only resolve_time_plan;
// the Scene is never rewritten with the choice. A checkpoint records the plan (to_json), so that a
// continued run keeps it.
//
// The choices, each explained where its constant lives:
//   scheme      "auto": ROCK4 where the wall is soft for its mesh, RKC2 where it is stiff
//               (auto_scheme.hpp); RKC2 with a fixed time.dt; else the scheme the scene names.
//   tolerance   "auto" (auto_tolerance.hpp): ROCK4 follows the mesh from t = 0 and loosens where the
//               run sees the creases; RKC2 starts loose and, where the wall creases, starts the run
//               again from t = 0 at a tight tolerance up to the crease time (the driver's rewind).
#include <optional>
#include <string>
#include <nlohmann/json_fwd.hpp>

#include "capsflow/core/geometry/surface_set.hpp"
#include "capsflow/core/named_enum.hpp"
#include "capsflow/core/stepping/time_scheme.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

struct Scene;

// What the run does when the wall creases at the mesh scale (auto_tolerance.hpp's criterion).
enum class CreaseAction {
  None,    // nothing: a given tolerance, a fixed step, or Heun
  Loosen,  // from there on the looser crease_tolerance (ROCK4's "auto")
  Rewind,  // start again from t = 0 at the tight crease_tolerance up to the crease time (RKC2's "auto")
};
inline constexpr NameTable<CreaseAction, 3> kCreaseActionNames{
    {{CreaseAction::None, "none"}, {CreaseAction::Loosen, "loosen"}, {CreaseAction::Rewind, "rewind"}}};
constexpr const auto& name_table(CreaseAction) { return kCreaseActionNames; }

// Where a run stands with respect to the creases; the run keeps it and its checkpoints carry it.
struct CreaseHistory {
  std::optional<double> seen_at;      // Loosen: γ̇t where the run saw the creases
  bool tightened = false;             // Rewind: the creases were seen and the tight tolerance holds ...
  std::optional<double> tight_until;  // ... up to this γ̇t (the discarded pass's crease time); for good if none
};

struct TimePlan {
  TimeScheme scheme = TimeScheme::Rkc;  // Rkc, Rock4 or Heun: never Auto
  bool chosen_by_auto = false;          // time.scheme = "auto" chose it
  bool error_control = false;           // a stabilised scheme with time.dt = "auto"
  bool tolerance_auto = false;          // time.tolerance = "auto" (error control only)
  double tolerance = 0;                 // the tolerance the run starts with (error control only)
  CreaseAction at_creases = CreaseAction::None;
  double crease_tolerance = 0;          // Loosen: from the creases on; Rewind: from t = 0 to the crease time
  double stiffness = 0;                 // analytic spectral radius at the reference shape, in flow rates
  std::string reason;                   // "auto: the analytic spectral radius 461 is below 800: …"

  // The tolerance in force at time t of a run whose crease history is h.
  double tolerance_in_force(const CreaseHistory& h, double t) const;
  nlohmann::json to_json() const;
  static TimePlan from_json(const nlohmann::json& j);
};

// The plan for a scene on its reference mesh.
TimePlan resolve_time_plan(const Scene& scene, const SurfaceMesh& reference);

// Several capsules (docs/several-capsules.md), each with its own scene (Scene::capsule_scene) and
// reference (the parts of `capsules`): the plan of the stiffest capsule — the largest analytic
// spectral radius, which sets the stable step of all — with, under time.tolerance = "auto", the
// tightest tolerance that any capsule's own plan of that scheme takes. One capsule: its plan.
TimePlan resolve_time_plan(const Scene& scene, const SurfaceSet& capsules);
int stiffest_capsule(const Scene& scene, const SurfaceSet& capsules);  // 0-based

// A restart keeps the checkpoint's plan unless it changes a key the plan is made of
// (time.scheme, time.tolerance, time.dt): then the plan is resolved anew for the new scene.
bool restart_keeps_time_plan(const Scene& stored, const Scene& next);

}  // namespace capsflow
