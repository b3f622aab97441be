#pragma once
// An 80-element Skalak sphere in a tube of radius 1.6 (confinement 0.625), to t = 0.2 ℓ/V: seconds
// per run. Tests turn it into a duct or a constriction with --set.
#include <string>
#include <vector>

#include "capsflow/core/scene/scene.hpp"

namespace capsflow::test {

inline constexpr const char* kTinyTubeScene = R"([mesh]
base = "icosahedron"
level = 1
shape = "sphere"
[wall]
model = "membrane"
law = "skalak"
[flow]
type = "poiseuille"
ca_s = 0.05
[time]
t_end = 0.2
[output]
every = 0.1
checkpoint_every = 0.1
[channel]
shape = "tube"
radius = 1.6
length = 9
element_size = 0.4
)";

inline Scene tiny_tube_scene(const std::vector<std::string>& overrides = {}) {
  return parse_scene(kTinyTubeScene, "tube.toml", overrides);
}

}  // namespace capsflow::test
