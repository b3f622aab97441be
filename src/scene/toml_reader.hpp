#pragma once
// Typed values from a parsed scene table, with one-line errors that say where the value came from:
// "FILE:LINE: section.key: problem", or "--set section.key: problem" for a key given on the command
// line (the option is the override's: --set, --vary, --levels).
#include <toml++/toml.h>

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "capsflow/core/types.hpp"

namespace capsflow::scene_detail {

class TomlReader {
 public:
  // overridden: "section.key" → the command-line option that set it.
  TomlReader(const toml::table& root, std::string name, std::map<std::string, std::string> overridden)
      : root_(root), name_(std::move(name)), overridden_(std::move(overridden)) {}

  // Throws SceneError "<where>section.key: what", at the key's line when the file gave it.
  [[noreturn]] void fail(const std::string& section, const std::string& key, const std::string& what) const;
  std::string where(const std::string& dotted_key, const toml::node* node) const;

  const toml::node* find(const std::string& section, const std::string& key) const;
  bool has(const std::string& section, const std::string& key) const { return find(section, key) != nullptr; }

  // Each returns nothing when the key is absent and throws on a value of the wrong type.
  // Finite; otherwise fails with "must be finite" and, when given, " and <accepted>" (the key's range).
  std::optional<double> number(const std::string& section, const std::string& key, const std::string& accepted = {}) const;
  std::optional<std::int64_t> integer(const std::string& section, const std::string& key) const;
  std::optional<bool> boolean(const std::string& section, const std::string& key) const;
  std::optional<std::string> string(const std::string& section, const std::string& key) const;
  std::optional<std::vector<std::string>> strings(const std::string& section, const std::string& key) const;
  std::optional<Mat3> matrix3(const std::string& section, const std::string& key) const;  // finite

  // Refuses a section or key that is not in `known` (section → its keys), listing the known ones.
  void check_known(const std::map<std::string, std::set<std::string>>& known) const;

 private:
  const toml::table& root_;
  std::string name_;
  std::map<std::string, std::string> overridden_;
};

// Applies one "section.key=value" to the table (the value read as TOML when it is one, otherwise as a
// string) and returns "section.key". `option` names the command-line option in its errors.
std::string apply_override(toml::table& root, const std::string& assignment, const std::string& option);

}  // namespace capsflow::scene_detail
