#include "capsflow/core/scene/scene_keys.hpp"

#include "key_table.hpp"

namespace capsflow {

std::vector<SceneKeyDoc> scene_key_docs() {
  std::vector<SceneKeyDoc> out;
  scene_detail::for_each_section([&](const auto& sec) {
    for (const auto& k : sec.keys) out.push_back({sec.name, k.name, k.type, k.default_text(), k.accepted, k.meaning});
  });
  return out;
}

std::string scene_key_table(const std::string& section) {
  std::string out = "| key | type | default | accepted | meaning |\n|---|---|---|---|---|\n";
  for (const SceneKeyDoc& d : scene_key_docs())
    if (d.section == section)
      out += "| `" + d.name + "` | " + d.type + " | " + d.default_value + " | " + d.accepted + " | " + d.meaning + " |\n";
  return out;
}

}  // namespace capsflow
