#pragma once
// The time integrators a scene can choose (time.scheme): damped RKC2 with error control
// (dynamics/rkc.hpp) or Heun at the stability-limited step (dynamics/heun.hpp).
#include "capsflow/core/named_enum.hpp"

namespace capsflow {

enum class TimeScheme { Rkc, Heun };
inline constexpr NameTable<TimeScheme, 2> kTimeSchemeNames{{{TimeScheme::Rkc, "rkc"}, {TimeScheme::Heun, "heun"}}};
constexpr const auto& name_table(TimeScheme) { return kTimeSchemeNames; }

}  // namespace capsflow
