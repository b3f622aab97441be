#pragma once
// The rules between the keys of a scene (each key on its own: scene_keys.cpp): values that follow
// from others, and checks that involve more than one key.
#include "capsflow/core/scene/scene.hpp"
#include "toml_reader.hpp"

namespace capsflow::scene_detail {

// Values that follow from others: Ca_s or Ca_v (from the one given and the thickness), the gradient
// of a named flow type, the scheme of time.scheme = "auto", a sphere's aspect ratio.
void derive(Scene& s);

// The checks across keys (ca_s or ca_v, the derived Ca_s, the gradient of each flow type); the message is placed at the
// key the user gave, found by the reader.
void check_rules(const TomlReader& r, const Scene& s);

}  // namespace capsflow::scene_detail
