#pragma once
// Which membrane law: the scene's `wall.law` before the moduli are known. The enumerators are in
// the order of the alternatives of MembraneLaw::Variant (laws.hpp checks it); each law's type owns
// its name (laws/*.hpp).
#include <optional>
#include <string>

namespace capsflow::shell {

enum class LawKind { GeneralizedHooke, NeoHookean, Skalak, MooneyRivlin };

/// The law's short name: "gh" | "nh" | "skalak" | "mr" (the scene and output spelling).
const char* to_string(LawKind kind);
/// The kind named `name` ("sk" is accepted for Skalak), or nothing.
std::optional<LawKind> law_from_name(const std::string& name);

}  // namespace capsflow::shell
