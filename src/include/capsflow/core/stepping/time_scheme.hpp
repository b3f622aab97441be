#pragma once
// The time integrators a scene can choose (time.scheme): damped RKC2 with error control
// (stepping/rkc.hpp) or Heun at the stability-limited step (stepping/heun.hpp). "auto" (the
// default) is resolved when the scene is read: RKC for a wall with bending stiffness (GSMB), Heun
// for a membrane (docs/time-integration.md §5.7 gives the measurements behind the choice).
#include "capsflow/core/named_enum.hpp"

namespace capsflow {

enum class TimeScheme { Rkc, Heun, Auto };
inline constexpr NameTable<TimeScheme, 3> kTimeSchemeNames{
    {{TimeScheme::Rkc, "rkc"}, {TimeScheme::Heun, "heun"}, {TimeScheme::Auto, "auto"}}};
constexpr const auto& name_table(TimeScheme) { return kTimeSchemeNames; }

}  // namespace capsflow
