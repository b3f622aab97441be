#pragma once
// The building blocks of the scene key table (scene_keys.cpp, where every key is declared once). A
// row binds a key's name to its member of a section struct, its default, its accepted values and its
// doc line; the helpers below (number, integer, boolean, choice, choice_list) derive from the row
// what every consumer needs: setting the default, reading and checking the TOML value (scene file
// and --set), writing it to JSON (summary.json, checkpoints) and TOML (to_toml, `capsflow info`),
// and documenting it (scene_keys.hpp, docs/scene-and-output.md §2).
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <type_traits>
#include <string>
#include <utility>
#include <vector>

#include "capsflow/core/named_enum.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "capsflow/core/user_text.hpp"
#include "toml_reader.hpp"

namespace capsflow::scene_detail {

// A number as messages and the docs print it: the shortest text that reads back to the same double,
// with the exponent unpadded (1e-9, not 1e-09).
std::string number_text(double v);
inline std::string number_text(std::int64_t v) { return std::to_string(v); }
inline std::string number_text(int v) { return std::to_string(v); }
// The TOML spelling of a double in to_toml: fmt's shortest round-trip form (unchanged since
// checkpoints began storing the scene).
inline std::string toml_number(double v) { return fmt::format("{}", v); }
inline std::string quoted(const std::string& s) { return "\"" + s + "\""; }

// The values a number or integer key accepts: an interval (each end open, closed or absent) and
// possibly one more value outside it (fluid.fmm_order: 0, or [4, 14]); `why` explains the bounds.
template <class T>
struct Range {
  std::optional<T> lo, hi;
  bool lo_open = false, hi_open = false;
  std::optional<T> also;
  std::string why;

  template <class U>
  bool contains(U v) const {
    if (also && v == static_cast<U>(*also)) return true;
    if (lo && (lo_open ? !(v > static_cast<U>(*lo)) : !(v >= static_cast<U>(*lo)))) return false;
    if (hi && (hi_open ? !(v < static_cast<U>(*hi)) : !(v <= static_cast<U>(*hi)))) return false;
    return true;
  }
  // "[0, 9]", "(0, 0.5]", "> 0", "≥ 0".
  std::string interval() const {
    if (lo && hi)
      return (lo_open ? "(" : "[") + number_text(*lo) + ", " + number_text(*hi) + (hi_open ? ")" : "]");
    if (lo) return (lo_open ? "> " : "≥ ") + number_text(*lo);
    if (hi) return (hi_open ? "< " : "≤ ") + number_text(*hi);
    return "any";
  }
  // The docs' "accepted" column: "[0, 9]", "0, or [4, 14]".
  std::string text() const { return also ? number_text(*also) + ", or " + interval() : interval(); }
  // The message's "must be …": "in [0, 9]", "> 0", "0 or in [4, 14]".
  std::string must() const {
    const std::string in = (lo && hi ? "in " : "") + interval();
    return also ? number_text(*also) + " or " + in : in;
  }
  // "-1 is out of range: must be in [0, 9] (why)".
  template <class U>
  std::string out_of_range(U v) const {
    return number_text(v) + " is out of range: must be " + must() + (why.empty() ? "" : " (" + why + ")");
  }
  Range because(std::string w) const {
    Range r = *this;
    r.why = std::move(w);
    return r;
  }
  Range or_value(T v) const {
    Range r = *this;
    r.also = v;
    return r;
  }
};

template <class T>
Range<T> closed(T lo, T hi) { return {lo, hi, false, false, std::nullopt, {}}; }        // [lo, hi]
template <class T>
Range<T> open_closed(T lo, T hi) { return {lo, hi, true, false, std::nullopt, {}}; }   // (lo, hi]
template <class T>
Range<T> open(T lo, T hi) { return {lo, hi, true, true, std::nullopt, {}}; }           // (lo, hi)
template <class T>
Range<T> above(T lo) { return {lo, std::nullopt, true, false, std::nullopt, {}}; }     // > lo
template <class T>
Range<T> at_least(T lo) { return {lo, std::nullopt, false, false, std::nullopt, {}}; } // ≥ lo

// One key of the section struct Spec, with every operation its consumers need.
template <class Spec>
struct Key {
  std::string name;
  std::string type, accepted, meaning;        // docs columns
  std::function<std::string()> default_text;  // docs "default" column
  std::string alternative;  // a key of the same section that --set of this one removes (flow.ca_s ↔ ca_v)
  std::function<void(Spec&)> set_default;
  // A given value is parsed and checked; an absent key leaves the member as it is.
  std::function<void(const TomlReader&, const std::string& section, Spec&)> read;
  std::function<nlohmann::json(const Spec&)> to_json;
  std::function<std::optional<std::string>(const Spec&)> to_toml;  // the value's text; nothing: no line

};

// One table of the scene ([mesh], [wall], ...): its keys in the order to_toml writes them.
template <class Spec>
struct Section {
  std::string name;
  Spec Scene::*member;
  std::vector<Key<Spec>> keys;
};

// ---- the helpers: one per kind of value ----

// A key's doc columns; the helpers below add its operations.
template <class Spec>
Key<Spec> documented(std::string name, std::string type, std::string accepted, std::string default_text,
                     std::string meaning) {
  Key<Spec> k;
  k.name = std::move(name);
  k.type = std::move(type);
  k.accepted = std::move(accepted);
  k.default_text = [text = std::move(default_text)] { return text; };
  k.meaning = std::move(meaning);
  return k;
}

// A number (T = double) or an integer (T = int: a TOML integer, checked against the range before it
// is narrowed, so 1e10 is out of range rather than wrapped around).
template <class Spec, class T>
Key<Spec> numeric(std::string name, T Spec::*m, T def, Range<T> range, std::string meaning) {
  constexpr bool is_double = std::is_same_v<T, double>;
  Key<Spec> k = documented<Spec>(name, is_double ? "number" : "integer", range.text(), "`" + number_text(def) + "`",
                                 std::move(meaning));
  k.set_default = [m, def](Spec& s) { s.*m = def; };
  k.read = [m, range, name](const TomlReader& r, const std::string& sec, Spec& s) {
    const auto v = is_double ? r.number(sec, name, range.must() + (range.why.empty() ? "" : " (" + range.why + ")"))
                             : std::optional<double>();
    const auto i = is_double ? std::optional<std::int64_t>() : r.integer(sec, name);
    if (v || i) {
      if (v ? !range.contains(*v) : !range.contains(*i)) r.fail(sec, name, v ? range.out_of_range(*v) : range.out_of_range(*i));
      s.*m = v ? static_cast<T>(*v) : static_cast<T>(*i);
    }
  };
  k.to_json = [m](const Spec& s) { return nlohmann::json(s.*m); };
  k.to_toml = [m](const Spec& s) {
    if constexpr (is_double) return std::optional<std::string>(toml_number(s.*m));
    else return std::optional<std::string>(std::to_string(s.*m));
  };
  return k;
}

template <class Spec>
Key<Spec> number(std::string name, double Spec::*m, double def, Range<double> range, std::string meaning) {
  return numeric(std::move(name), m, def, std::move(range), std::move(meaning));
}

template <class Spec>
Key<Spec> integer(std::string name, int Spec::*m, int def, Range<int> range, std::string meaning) {
  return numeric(std::move(name), m, def, std::move(range), std::move(meaning));
}

template <class Spec>
Key<Spec> boolean(std::string name, bool Spec::*m, bool def, std::string meaning) {
  Key<Spec> k = documented<Spec>(name, "boolean", "`true`, `false`", def ? "`true`" : "`false`", std::move(meaning));
  k.set_default = [m, def](Spec& s) { s.*m = def; };
  k.read = [m, name](const TomlReader& r, const std::string& sec, Spec& s) {
    if (const std::optional<bool> v = r.boolean(sec, name)) s.*m = *v;
  };
  k.to_json = [m](const Spec& s) { return nlohmann::json(s.*m); };
  k.to_toml = [m](const Spec& s) { return std::optional<std::string>(s.*m ? "true" : "false"); };
  return k;
}

// The spellings of a named choice, in table order.
template <class E>
using Spellings = std::vector<std::pair<E, std::string>>;

template <class E>
Spellings<E> spellings_of_table() {
  Spellings<E> out;
  for (const auto& [v, name] : name_table(E{})) out.emplace_back(v, name);
  return out;
}

template <class E>
std::string spelling(const Spellings<E>& names, E v) {
  for (const auto& [e, name] : names)
    if (e == v) return name;
  return "?";
}

// "'gpu' is not one of: auto, fmm, direct" (a long value abbreviated).
template <class E>
E parse_spelling(const Spellings<E>& names, const std::string& given, const TomlReader& r, const std::string& sec,
                 const std::string& key) {
  std::string list;
  for (const auto& [e, name] : names) {
    if (given == name) return e;
    list += (list.empty() ? "" : ", ") + name;
  }
  r.fail(sec, key, "'" + abbreviate(given) + "' is not one of: " + list);
}

template <class E>
std::string accepted_spellings(const Spellings<E>& names) {
  std::string out;
  for (const auto& [e, name] : names) out += (out.empty() ? "`\"" : ", `\"") + name + "\"`";
  return out;
}

// A named choice with the given spellings (the enum's name table by default).
template <class Spec, class E>
Key<Spec> choice(std::string name, E Spec::*m, E def, std::string meaning, Spellings<E> names = spellings_of_table<E>()) {
  Key<Spec> k = documented<Spec>(name, "string", accepted_spellings(names), "`\"" + spelling(names, def) + "\"`",
                                 std::move(meaning));
  k.set_default = [m, def](Spec& s) { s.*m = def; };
  k.read = [m, name, names](const TomlReader& r, const std::string& sec, Spec& s) {
    if (const std::optional<std::string> v = r.string(sec, name)) s.*m = parse_spelling(names, *v, r, sec, name);
  };
  k.to_json = [m, names](const Spec& s) { return nlohmann::json(spelling(names, s.*m)); };
  k.to_toml = [m, names](const Spec& s) { return std::optional<std::string>(quoted(spelling(names, s.*m))); };
  return k;
}

// A list of named choices, empty by default. A choice given twice counts once, at its first place:
// folded rather than refused because checkpoints store the list as it was given, and a restart
// must accept what a checkpoint holds (200 000 copies of one field were once stored verbatim).
template <class Spec, class E>
Key<Spec> choice_list(std::string name, std::vector<E> Spec::*m, std::string meaning) {
  const Spellings<E> names = spellings_of_table<E>();
  Key<Spec> k = documented<Spec>(name, "array of strings", accepted_spellings(names), "`[]`", std::move(meaning));
  k.set_default = [m](Spec& s) { (s.*m).clear(); };
  k.read = [m, name, names](const TomlReader& r, const std::string& sec, Spec& s) {
    if (const std::optional<std::vector<std::string>> v = r.strings(sec, name)) {
      std::vector<E> out;
      for (const std::string& given : *v) {
        const E e = parse_spelling(names, given, r, sec, name);
        if (std::find(out.begin(), out.end(), e) == out.end()) out.push_back(e);
      }
      s.*m = std::move(out);
    }
  };
  k.to_json = [m, names](const Spec& s) {
    nlohmann::json j = nlohmann::json::array();
    for (E e : s.*m) j.push_back(spelling(names, e));
    return j;
  };
  k.to_toml = [m, names](const Spec& s) {
    std::string out;
    for (E e : s.*m) out += (out.empty() ? "" : ", ") + quoted(spelling(names, e));
    return std::optional<std::string>("[" + out + "]");
  };
  return k;
}

// ---- the table (scene_keys.cpp) ----
const Section<MeshSpec>& mesh_keys();
const Section<WallSpec>& wall_keys();
const Section<FlowSpec>& flow_keys();
const Section<TimeSpec>& time_keys();
const Section<FluidSpec>& fluid_keys();
const Section<OutputSpec>& output_keys();
const Section<LayoutSpec>& layout_keys();
const Section<ContactSpec>& contact_keys();
const Section<ChannelSpec>& channel_keys();

// Calls f(section) for every section, in the order of the TOML file.
template <class F>
void for_each_section(F&& f) {
  f(mesh_keys());
  f(wall_keys());
  f(flow_keys());
  f(time_keys());
  f(fluid_keys());
  f(output_keys());
  f(layout_keys());
  f(contact_keys());
  f(channel_keys());
}

// The accepted Ca_s, whether given (flow.ca_s) or derived from flow.ca_v and the thickness.
const Range<double>& capillary_range();

}  // namespace capsflow::scene_detail
