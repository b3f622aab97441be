// The key table (src/scene/scene_keys.cpp) against every other place a key shows up: the tables of
// docs/scene-and-output.md §2, a default-constructed Scene, the library option structs whose
// defaults the scene takes, and the scene TOML that checkpoints written before the table hold.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "capsflow/core/scene/scene_keys.hpp"
#include "capsflow/shell/gsmb_wall.hpp"

using namespace capsflow;

namespace {

std::string read_docs() {
  std::ifstream in(std::filesystem::path(CAPSFLOW_SOURCE_DIR) / "docs" / "scene-and-output.md");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The table under the docs heading that names [section]: its consecutive '|' lines.
std::string docs_table(const std::string& docs, const std::string& section) {
  const std::string heading = "`[" + section + "]`\n";
  const auto h = docs.find(heading);
  if (h == std::string::npos) return "(no heading ending in " + heading + ")";
  const auto start = docs.find("\n|", h);
  if (start == std::string::npos) return "(no table)";
  std::string out;
  std::istringstream lines(docs.substr(start + 1));
  for (std::string line; std::getline(lines, line) && !line.empty() && line[0] == '|';) out += line + "\n";
  return out;
}

}  // namespace

// The docs' key tables are the table's: a key added, renamed, re-ranged or re-documented in
// scene_keys.cpp fails here until the docs are pasted from the message.
TEST(SceneKeys, DocsTablesAreTheKeyTable) {
  const std::string docs = read_docs();
  for (const std::string section : {"mesh", "wall", "flow", "time", "fluid", "output", "layout", "contact"}) {
    const std::string expected = scene_key_table(section);
    EXPECT_EQ(docs_table(docs, section), expected)
        << "docs/scene-and-output.md, table of [" << section << "]: replace it by\n" << expected;
  }
}

TEST(SceneKeys, EveryKeyIsDocumentedAndAcceptedOnce) {
  const std::vector<SceneKeyDoc> keys = scene_key_docs();
  std::set<std::string> names;
  for (const SceneKeyDoc& k : keys) {
    EXPECT_TRUE(names.insert(k.section + "." + k.name).second) << k.section << "." << k.name;
    EXPECT_FALSE(k.type.empty() || k.default_value.empty() || k.meaning.empty()) << k.section << "." << k.name;
  }
  // Every documented key is in the scene's JSON (summary.json) under its name.
  const nlohmann::json j = to_json(parse_scene("", "empty"));
  for (const SceneKeyDoc& k : keys) EXPECT_TRUE(j.at(k.section).contains(k.name)) << k.section << "." << k.name;
}

// A default-constructed Scene is the scene of an empty file: its sections take the table's
// defaults, and the derived values (Ca_s, the gradient, the scheme) follow as when parsing.
TEST(SceneKeys, DefaultSceneIsTheEmptyFile) {
  EXPECT_EQ(to_toml(Scene{}), to_toml(parse_scene("", "empty")));
  EXPECT_EQ(to_json(Scene{}), to_json(parse_scene("", "empty")));
  EXPECT_EQ(MeshSpec{}.level, Scene{}.mesh.level);  // a section alone has its defaults too
}

// Defaults that a library option struct also holds are read from it, not restated.
TEST(SceneKeys, LibraryDefaultsAreTheScenes) {
  const Scene s;
  const shell::GsmbOptions gsmb;
  EXPECT_EQ(s.wall.thickness, gsmb.thickness);
  EXPECT_EQ(s.wall.poisson, gsmb.poisson);
  EXPECT_EQ(s.wall.max_newton, gsmb.max_newton);
  const SingleLayerOptions bie;
  EXPECT_EQ(s.fluid.backend, bie.backend);
  EXPECT_EQ(s.fluid.tolerance, bie.tolerance);
  EXPECT_EQ(s.fluid.geometry, bie.geometry);
  EXPECT_EQ(s.fluid.fmm_order, bie.fmm_order);
  EXPECT_EQ(s.fluid.verify_every, bie.verify_every);
}

// The resolved scene as 8e4abd4 (before the key table) wrote it into checkpoints (scene_toml) and
// printed it in `capsflow info` (this text is that output, with a non-default value for every key
// that has one): it still reads, and is written back byte for byte, so old checkpoints restart and
// the study's same-scene check keeps working.
TEST(SceneKeys, TomlWrittenBeforeTheTableReadsAndIsWrittenTheSame) {
  const std::string stored = R"([mesh]
base = "octahedron"
level = 3
shape = "sphere"
aspect = 1
axis = 3
file = "/x/y.off"

[wall]
model = "gsmb"
law = "mr"
thickness = 0.03
poisson = 0.5
skalak_c = 1
mooney_rivlin_psi = 0.3
max_newton = 17

[flow]
type = "linear"
ca_s = 0.41000000000000003  # ca_v = ca_s * thickness = 0.0123
gradient = [[0, 1, 0], [0, 0, 0], [0.5, 0, 0]]

[time]
scheme = "heun"
tolerance = 3e-07
dt = 0.001
dt_safety = 0.7
t_end = 2
stop_at_steady = true
steady_tol = 1e-05
stop_on = ["unresolved_folds", "no_equilibrium"]

[fluid]
backend = "direct"
tolerance = 1e-06
geometry = "curved"
volume_correction = false
fmm_order = 9
verify_every = 7

[output]
every = 0.1
fields = ["velocity", "energy"]
checkpoint_every = 0
)";
  // Keys added since (fluid.far_rule, fmm_leaf_size, viscosity_ratio, max_gmres, reuse_identity_term, wall.prestress, initial_stretch) are written with their defaults, the rest unchanged.
  std::string expected = stored;
  expected.replace(expected.find("max_newton = 17\n"), 16, "max_newton = 17\nprestress = 0\ninitial_stretch = 1\n");
  expected.replace(expected.find("verify_every = 7\n"), 17, "verify_every = 7\nviscosity_ratio = 1\nmax_gmres = 100\nreuse_identity_term = true\n");
  expected.replace(expected.find("fmm_order = 9\n"), 14, "fmm_order = 9\nfmm_leaf_size = 0\n");
  expected.replace(expected.find("geometry = \"curved\"\n"), 20, "geometry = \"curved\"\nfar_rule = \"auto\"\n");
  // ... and the sections of several capsules, with their defaults (one capsule, no repulsion).
  expected += "\n[layout]\ncount = 1\ndx = 0\ndy = 0\ndz = 0\n\n[contact]\nrepulsion_range = 0\nrepulsion_strength = 1\nmin_gap = 0.05\n";
  // ... and the channel's, with its defaults (none: unbounded flow).
  expected += "\n[channel]\nshape = \"none\"\nradius = 1.25\nlength = 10\nelement_size = \"auto\"\n"
              "constriction_height = 0.5\nconstriction_width = 1\nconstriction_length = 1\nconstriction_center = 2\n"
              "constriction_taper = \"auto\"\n";
  EXPECT_EQ(to_toml(parse_scene(stored, "checkpoint")), expected);
}

// Docs §2.9 still listed `time.stop_on` as "planned, not implemented" long after it was.
// When §2.9 lists keys as missing, none of them may be a key of the table.
TEST(SceneKeys, DocsCallNoExistingKeyMissing) {
  const std::string docs = read_docs();
  const auto begin = docs.find("### 2.9"), end = docs.find("\n## ", begin);
  ASSERT_NE(begin, std::string::npos);
  const std::string section = docs.substr(begin, end - begin);
  if (section.find("not implemented") == std::string::npos && section.find("lanned") == std::string::npos) return;
  for (const SceneKeyDoc& k : scene_key_docs())
    EXPECT_EQ(section.find("`" + k.section + "." + k.name + "`"), std::string::npos) << k.section << "." << k.name;
}
