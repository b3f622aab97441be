#include "toml_reader.hpp"

#include <cctype>
#include <cmath>

#include "capsflow/core/scene/scene.hpp"
#include "capsflow/core/user_text.hpp"

namespace capsflow::scene_detail {

namespace {

std::string type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::array: return "an array";
    case toml::node_type::table: return "a table";
    default: return "a date/time";
  }
}

std::string join(const std::set<std::string>& s) {
  std::string out;
  for (const auto& k : s) out += (out.empty() ? "" : ", ") + k;
  return out;
}

bool from_file(const toml::node* node) { return node && node->source().begin.line > 0; }

}  // namespace

std::string TomlReader::where(const std::string& key, const toml::node* node) const {
  if (auto it = overridden_.find(key); it != overridden_.end()) return it->second + " " + abbreviate(key) + ": ";
  for (const auto& [k, option] : overridden_)  // a section that only an override created
    if (k.compare(0, key.size() + 1, key + ".") == 0 && !from_file(node)) return option + " " + abbreviate(k) + ": ";
  if (from_file(node)) return name_ + ":" + std::to_string(node->source().begin.line) + ": " + abbreviate(key) + ": ";
  return name_ + ": " + abbreviate(key) + ": ";
}

void TomlReader::fail(const std::string& section, const std::string& key, const std::string& what) const {
  throw SceneError(where(section + "." + key, find(section, key)) + what);
}

const toml::node* TomlReader::find(const std::string& section, const std::string& key) const {
  const toml::node* sec = root_.get(section);
  if (!sec || !sec->is_table()) return nullptr;
  return sec->as_table()->get(key);
}

std::optional<double> TomlReader::number(const std::string& s, const std::string& k, const std::string& accepted) const {
  const toml::node* n = find(s, k);
  if (!n) return std::nullopt;
  double v = 0;
  if (n->is_integer()) v = static_cast<double>(n->as_integer()->get());
  else if (n->is_floating_point()) v = n->as_floating_point()->get();
  else fail(s, k, "expected a number, got " + type_name(*n));
  if (!std::isfinite(v)) fail(s, k, "must be finite" + (accepted.empty() ? std::string() : " and " + accepted));
  return v;
}

std::optional<std::int64_t> TomlReader::integer(const std::string& s, const std::string& k) const {
  const toml::node* n = find(s, k);
  if (!n) return std::nullopt;
  if (!n->is_integer()) fail(s, k, "expected an integer, got " + type_name(*n));
  return n->as_integer()->get();
}

std::optional<bool> TomlReader::boolean(const std::string& s, const std::string& k) const {
  const toml::node* n = find(s, k);
  if (!n) return std::nullopt;
  if (!n->is_boolean()) fail(s, k, "expected true or false, got " + type_name(*n));
  return n->as_boolean()->get();
}

std::optional<std::string> TomlReader::string(const std::string& s, const std::string& k) const {
  const toml::node* n = find(s, k);
  if (!n) return std::nullopt;
  if (!n->is_string()) fail(s, k, "expected a string, got " + type_name(*n));
  return n->as_string()->get();
}

std::optional<std::vector<std::string>> TomlReader::strings(const std::string& s, const std::string& k) const {
  const toml::node* n = find(s, k);
  if (!n) return std::nullopt;
  if (!n->is_array()) fail(s, k, "expected an array of strings, got " + type_name(*n));
  std::vector<std::string> out;
  for (const auto& e : *n->as_array()) {
    if (!e.is_string()) fail(s, k, "expected an array of strings");
    out.push_back(e.as_string()->get());
  }
  return out;
}

std::optional<Mat3> TomlReader::matrix3(const std::string& s, const std::string& k) const {
  const toml::node* n = find(s, k);
  if (!n) return std::nullopt;
  const std::string msg = "expected a 3×3 array of numbers [[..],[..],[..]]";
  if (!n->is_array() || n->as_array()->size() != 3) fail(s, k, msg);
  Mat3 out;
  for (int i = 0; i < 3; ++i) {
    const toml::node& row = *n->as_array()->get(static_cast<std::size_t>(i));
    if (!row.is_array() || row.as_array()->size() != 3) fail(s, k, msg);
    for (int j = 0; j < 3; ++j) {
      const toml::node& v = *row.as_array()->get(static_cast<std::size_t>(j));
      if (v.is_integer()) out(i, j) = static_cast<double>(v.as_integer()->get());
      else if (v.is_floating_point()) out(i, j) = v.as_floating_point()->get();
      else fail(s, k, msg);
      if (!std::isfinite(out(i, j))) fail(s, k, "entries must be finite");
    }
  }
  return out;
}

void TomlReader::check_known(const std::map<std::string, std::set<std::string>>& known) const {
  for (const auto& [sec, node] : root_) {
    const std::string s(sec.str());
    auto it = known.find(s);
    if (it == known.end()) {
      std::set<std::string> sections;
      for (const auto& [k, v] : known) sections.insert(k);
      throw SceneError(where(s, &node) + "unknown section [" + abbreviate(s) + "] (known: " + join(sections) + ")");
    }
    if (!node.is_table()) throw SceneError(where(s, &node) + "expected a table [" + abbreviate(s) + "]");
    for (const auto& [key, val] : *node.as_table()) {
      const std::string k(key.str());
      if (!it->second.count(k))
        throw SceneError(where(s + "." + k, &val) + "unknown key (known in [" + s + "]: " + join(it->second) + ")");
    }
  }
}

namespace {

bool has_line_break(const std::string& s) { return s.find_first_of("\n\r") != std::string::npos; }

// A decimal integer as TOML writes one (sign, digits, underscores between digits).
bool looks_like_integer(const std::string& s) {
  std::size_t i = (!s.empty() && (s[0] == '+' || s[0] == '-')) ? 1 : 0;
  if (i == s.size()) return false;
  for (; i < s.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(s[i])) && s[i] != '_') return false;
  return true;
}

}  // namespace

std::string apply_override(toml::table& root, const std::string& assignment, const std::string& option) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw SceneError(option + " " + abbreviate(assignment) + ": expected key.path=value");
  const std::string key = assignment.substr(0, eq), value = assignment.substr(eq + 1);
  const auto dot = key.find('.');
  // '#' would start a TOML comment and a line break a second assignment: neither is in any key.
  if (dot == std::string::npos || key.find('.', dot + 1) != std::string::npos || key.find('#') != std::string::npos ||
      has_line_break(key))
    throw SceneError(option + " " + abbreviate(assignment) + ": key must be section.key (e.g. time.t_end)");
  // A line break in the value once ended the value there and read the rest as another line of
  // TOML (`--set $'time.t_end=1\nmesh.level=1'` dropped mesh.level=1 without a word).
  if (has_line_break(value))
    throw SceneError(option + " " + abbreviate(key) + ": the value " + abbreviate(value) +
                     " has a line break: one key per " + option);
  const std::string sec = key.substr(0, dot), leaf = key.substr(dot + 1);
  toml::table tmp;
  try {
    tmp = toml::parse("v = " + value);
    // '#' outside a string starts a TOML comment: `0.5#x` read as 0.5. Inside brackets the
    // comment swallows the closing one, so only a '#' in a string still parses.
    if (value.find('#') != std::string::npos) {
      try {
        (void)toml::parse("v = [" + value + "]");
      } catch (const toml::parse_error&) {
        throw SceneError(option + " " + abbreviate(key) + ": the value " + abbreviate(value) +
                         " has a '#', which TOML reads as the start of a comment: quote a string that contains one");
      }
    }
  } catch (const toml::parse_error&) {
    // Not a TOML value: taken as a string (--set wall.law=nh), unless it is an integer TOML
    // cannot hold (a 31-digit integer was reported as "expected an integer, got a string").
    if (looks_like_integer(value))
      throw SceneError(option + " " + abbreviate(key) + ": " + abbreviate(value) +
                       " is out of range: integers have at most 64 bits (magnitude below 9.2e18)");
    tmp = toml::table{{"v", value}};
  }
  if (!root.contains(sec)) root.insert(sec, toml::table{});
  toml::table* t = root.get(sec)->as_table();
  if (!t) throw SceneError(option + " " + abbreviate(assignment) + ": [" + abbreviate(sec) + "] is not a table");
  t->insert_or_assign(leaf, *tmp.get("v"));
  return key;
}

}  // namespace capsflow::scene_detail
