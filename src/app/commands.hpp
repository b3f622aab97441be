#pragma once
// Sub-commands of the capsflow executable (design.md §5).
#include <string>
#include <vector>

namespace capsflow::app {

struct InfoOptions {
  std::string scene_path;  // empty: built-in default scene
  std::vector<std::string> overrides;
};
int info_command(const InfoOptions& opt);

}  // namespace capsflow::app
