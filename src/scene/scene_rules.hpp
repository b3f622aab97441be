#pragma once
// The rules between the keys of a scene (each key on its own: scene_keys.cpp): values that follow
// from others, and checks that involve more than one key.
#include "capsflow/core/scene/scene.hpp"
#include "toml_reader.hpp"

namespace capsflow::scene_detail {

// The most steps (t_end/dt, for a fixed dt) a run may need: 1e9 steps of one millisecond each are
// 11 days, so a larger count is a typo (time.dt = 1e-300 asked for 5e300).
inline constexpr double kMaxSteps = 1e9;
// The most outputs (t_end/every) and checkpoints (t_end/checkpoint_every): every output adds a
// run.h5 group with the positions (642 nodes × 3 × 8 bytes = 15 kB at 1280 elements) and a CSV row,
// so 1e7 of them are already 150 GB.
inline constexpr double kMaxOutputs = 1e7;
// The most capsules ([layout] count, [[capsule]] tables): `capsflow info --set layout.count=100
// --set layout.dx=3` estimates 854 MB for 100 capsules of 1280 elements, so 1000 already need ~8.5 GB.
inline constexpr int kMaxCapsules = 1000;

// Values that follow from others: Ca_s or Ca_v (from the one given and the thickness), the gradient
// of a named flow type, the scheme of time.scheme = "auto", a sphere's aspect ratio.
void derive(Scene& s);

// The checks across keys (ca_s or ca_v, the derived Ca_s, the gradient of each flow type, the step,
// output and checkpoint counts to time.t_end, counted from 0 also on a restart); the message is placed at the
// key the user gave, found by the reader.
void check_rules(const TomlReader& r, const Scene& s);

}  // namespace capsflow::scene_detail
