#pragma once
// The scene keys as documentation, read off the key table (src/scene/scene_keys.cpp, where each key
// is declared once): for docs/scene-and-output.md §2 (whose tables a unit test keeps equal to these),
// for `capsflow info --keys` and for the Python package.
#include <string>
#include <vector>

namespace capsflow {

struct SceneKeyDoc {
  std::string section, name;  // "mesh", "level"
  std::string type;           // "integer", "number", "string", "boolean", "array of strings", ...
  std::string default_value;  // as the docs print it: "`4`", "`\"auto\"`", "none"
  std::string accepted;       // "[0, 9]", "> 0", "`\"gh\"`, `\"nh\"`"
  std::string meaning;        // one line, markdown
};

// Every key, section by section in the order of a scene file.
std::vector<SceneKeyDoc> scene_key_docs();

// The markdown table of one section's keys (header included), as docs/scene-and-output.md §2 has it.
std::string scene_key_table(const std::string& section);

}  // namespace capsflow
