#pragma once
// Enums with one name table each: `name_table(E{})` (an overload found by argument-dependent
// lookup) lists (value, spelling) pairs, and to_string / from_string / name_list are generated
// from it, so each spelling is written once.
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>

namespace capsflow {

template <class E, std::size_t N>
using NameTable = std::array<std::pair<E, const char*>, N>;

template <class E, class = decltype(name_table(E{}))>
const char* to_string(E e) {
  for (const auto& [v, name] : name_table(E{}))
    if (v == e) return name;
  return "?";
}

template <class E, class = decltype(name_table(E{}))>
std::optional<E> from_string(const std::string& s) {
  for (const auto& [v, name] : name_table(E{}))
    if (s == name) return v;
  return std::nullopt;
}

// "a, b, c": the accepted spellings, for error messages.
template <class E, class = decltype(name_table(E{}))>
std::string name_list() {
  std::string out;
  for (const auto& [v, name] : name_table(E{})) out += (out.empty() ? "" : ", ") + std::string(name);
  return out;
}

}  // namespace capsflow
