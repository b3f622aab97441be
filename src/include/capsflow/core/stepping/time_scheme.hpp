#pragma once
// The time integrators a scene can choose (time.scheme): damped RKC2 (stepping/rkc2.hpp) or the
// fourth-order ROCK4 (stepping/rock4.hpp), both stabilised explicit steps with error control, or
// Heun at the stability-limited step (stepping/heun.hpp). "auto" (the default) is resolved with the
// mesh by the time plan: ROCK4 where the wall is soft for its mesh, RKC2 where it is stiff
// (stepping/time_plan.hpp, docs/time-integration.md §5.2).
#include "capsflow/core/named_enum.hpp"

namespace capsflow {

enum class TimeScheme { Rkc, Rock4, Heun, Auto };
inline constexpr NameTable<TimeScheme, 4> kTimeSchemeNames{
    {{TimeScheme::Rkc, "rkc"}, {TimeScheme::Rock4, "rock4"}, {TimeScheme::Heun, "heun"}, {TimeScheme::Auto, "auto"}}};
constexpr const auto& name_table(TimeScheme) { return kTimeSchemeNames; }

// RKC2 and ROCK4: stages from the spectral radius, a tolerance-controlled step, dense output.
// "auto" always chooses one of the two.
constexpr bool is_stabilized(TimeScheme s) { return s != TimeScheme::Heun; }

}  // namespace capsflow
