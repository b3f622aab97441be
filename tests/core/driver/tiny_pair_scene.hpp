#pragma once
// Two Skalak membrane spheres of 80 elements in simple shear v = x2 e1, run to γ̇t = 0.4 with rows
// every 0.2: seconds per run. Without [layout], one capsule; tests add their layout with --set.
namespace capsflow::test {

inline constexpr const char* kTinyShearScene = R"([mesh]
base = "icosahedron"
level = 1
shape = "sphere"
[wall]
model = "membrane"
law = "skalak"
[flow]
type = "simple_shear"
ca_s = 0.05
[time]
t_end = 0.4
[output]
every = 0.2
checkpoint_every = 0.2
)";

}  // namespace capsflow::test
