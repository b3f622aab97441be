#pragma once
// The named conditions the health monitor detects (health/health_monitor.hpp); a scene may stop
// on any of them with `time.stop_on = [...]` (docs/health-monitors.md).
#include "capsflow/core/named_enum.hpp"

namespace capsflow {

enum class HealthCondition { MeshScaleBuckling, UnresolvedFolds, ElementQuality, NoEquilibrium, SurfaceGap };
inline constexpr NameTable<HealthCondition, 5> kHealthConditionNames{{{HealthCondition::MeshScaleBuckling, "mesh_scale_buckling"},
                                                                      {HealthCondition::UnresolvedFolds, "unresolved_folds"},
                                                                      {HealthCondition::ElementQuality, "element_quality"},
                                                                      {HealthCondition::NoEquilibrium, "no_equilibrium"},
                                                                      {HealthCondition::SurfaceGap, "surface_gap"}}};
constexpr const auto& name_table(HealthCondition) { return kHealthConditionNames; }

}  // namespace capsflow
