// Several capsules in a scene: [layout]'s row, [[capsule]] tables, and the refusals, each naming
// the capsule and the key (docs/scene-and-output.md §2.10–2.12).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "capsflow/core/scene/scene.hpp"

namespace capsflow {
namespace {

std::string refusal(const std::string& toml, const std::vector<std::string>& overrides = {}) {
  try {
    parse_scene(toml, "s.toml", overrides);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(SeveralCapsulesScene, OneCapsuleIsWhereItsMeshIs) {
  const Scene s = parse_scene("", "s.toml");
  ASSERT_EQ(s.capsule_centers().size(), 1u);
  EXPECT_TRUE(s.capsule_centers()[0].isZero()) << "no layout: the mesh is not moved";
}

TEST(SeveralCapsulesScene, TheLayoutIsARowCentredOnTheOrigin) {
  const Scene s = parse_scene("[layout]\ncount = 3\ndx = 3\ndz = -1\n", "s.toml");
  const auto c = s.capsule_centers();
  ASSERT_EQ(c.size(), 3u);
  // k − (count − 1)/2 = −1, 0, 1 times the step (3, 0, −1): exact in binary.
  EXPECT_EQ(c[0], Vec3(-3, 0, 1));
  EXPECT_EQ(c[1], Vec3(0, 0, 0));
  EXPECT_EQ(c[2], Vec3(3, 0, -1));
  // --set reaches the layout's scalars (what a study varies).
  EXPECT_EQ(parse_scene("", "s.toml", {"layout.count=2", "layout.dy=0.5"}).capsule_centers()[1], Vec3(0, 0.25, 0));
}

TEST(SeveralCapsulesScene, CapsuleTablesGiveTheCentresAndSurviveTheCanonicalToml) {
  const Scene s = parse_scene("[[capsule]]\ncenter = [1, 2, 3]\n[[capsule]]\ncenter = [-1.5, 0, 1e-3]\n", "s.toml");
  ASSERT_EQ(s.capsule_centers().size(), 2u);
  EXPECT_EQ(s.capsule_centers()[1], Vec3(-1.5, 0, 1e-3));
  // A checkpoint stores to_toml(scene): a restart must find the same capsules.
  const Scene back = parse_scene(to_toml(s), "checkpoint");
  ASSERT_EQ(back.capsule_centers().size(), 2u);
  EXPECT_EQ(back.capsule_centers()[0], Vec3(1, 2, 3));
  EXPECT_EQ(back.capsule_centers()[1], Vec3(-1.5, 0, 1e-3));
  EXPECT_EQ(to_json(s).at("capsule").size(), 2u);
}

TEST(SeveralCapsulesScene, BadCapsuleArraysAreRefusedNamingTheCapsuleAndTheKey) {
  EXPECT_EQ(refusal("capsule = []\n"), "s.toml:1: capsule: an empty array: give one [[capsule]] table per capsule, or none");
  EXPECT_EQ(refusal("capsule = 3\n"),
            "s.toml:1: capsule: expected an array of tables [[capsule]] (each with its center = [x, y, z])");
  EXPECT_EQ(refusal("[[capsule]]\ncenter = [0, 0, 0]\n[[capsule]]\ncentre = [0, 0, 4]\n"),
            "s.toml:3: capsule 2: unknown key 'centre' (known in [[capsule]]: center, and [capsule.mesh], [capsule.wall] "
            "tables)");
  EXPECT_EQ(refusal("[[capsule]]\ncenter = [0, 0]\n"), "s.toml:1: capsule 1: center: expected an array of 3 finite numbers [x, y, z]");
  EXPECT_EQ(refusal("[[capsule]]\ncenter = [0, nan, 0]\n"),
            "s.toml:1: capsule 1: center: expected an array of 3 finite numbers [x, y, z]");
  EXPECT_EQ(refusal("[[capsule]]\n"), "s.toml:1: capsule 1: center: required (the capsule's position [x, y, z], in ℓ)");
  std::string many;
  for (int k = 0; k < 1001; ++k) many += "[[capsule]]\ncenter = [" + std::to_string(3 * k) + ", 0, 0]\n";
  EXPECT_EQ(refusal(many), "s.toml:1: capsule: 1001 [[capsule]] tables: at most 1000 capsules");
  EXPECT_NE(refusal("", {"layout.count=100000"}).find("layout.count: 100000 is out of range: must be in [1, 1000]"),
            std::string::npos);
}

TEST(SeveralCapsulesScene, ACapsuleMayHaveMeshAndWallKeysOfItsOwn) {
  const std::string toml = R"([wall]
model = "membrane"
thickness = 0.03
[flow]
ca_v = 0.003
[[capsule]]
center = [-3, 0, 0]
[[capsule]]
center = [3, 0, 0]
mesh.level = 2
[capsule.wall]
model = "gsmb"
thickness = 0.06
)";
  const Scene s = parse_scene(toml, "s.toml");
  EXPECT_FALSE(s.capsules_alike());
  EXPECT_EQ(s.capsule_scene(0).wall.model, WallModel::Membrane) << "capsule 1 keeps the scene's wall";
  EXPECT_EQ(s.capsule_scene(0).mesh.level, s.mesh.level);
  const Scene two = s.capsule_scene(1);
  EXPECT_EQ(two.mesh.level, 2);
  EXPECT_EQ(two.mesh.shape, s.mesh.shape) << "the keys it does not give are the scene's";
  EXPECT_EQ(two.wall.model, WallModel::Gsmb);
  EXPECT_EQ(two.wall.poisson, s.wall.poisson);
  // Ca_s = Ca_v/thickness follows each capsule's thickness (the scene gives Ca_v): 0.003/0.06.
  EXPECT_DOUBLE_EQ(two.flow.ca_s, 0.05);
  EXPECT_DOUBLE_EQ(s.capsule_scene(0).flow.ca_s, 0.1);
  // A checkpoint's canonical TOML keeps them.
  const Scene back = parse_scene(to_toml(s), "checkpoint");
  EXPECT_EQ(back.capsule_scene(1).mesh.level, 2);
  EXPECT_EQ(back.capsule_scene(1).wall.thickness, 0.06);
  EXPECT_FALSE(back.capsules[0].wall.has_value()) << "capsule 1 still has no keys of its own";
  // Refusals name the capsule, the file's line and the key.
  EXPECT_EQ(refusal("[[capsule]]\ncenter = [0, 0, 0]\n[capsule.wall]\nthickness = 1\n"),
            "capsule 1: s.toml:4: wall.thickness: 1 is out of range: must be in (0, 0.5] (h/ℓ)");
  EXPECT_EQ(refusal("[[capsule]]\ncenter = [0, 0, 0]\nmesh.levle = 1\n"),
            "capsule 1: s.toml:3: mesh.levle: unknown key (known in [mesh]: aspect, axis, base, file, level, shape)");
  EXPECT_EQ(refusal("[[capsule]]\ncenter = [0, 0, 0]\nwall = 3\n"), "s.toml:1: capsule 1: wall: expected a table of wall keys");
}

TEST(SeveralCapsulesScene, ContradictionsAreRefusedNamingTheKey) {
  EXPECT_EQ(refusal("[layout]\ncount = 2\n[[capsule]]\ncenter = [0, 0, 0]\n"),
            "s.toml:2: layout.count: give either a [layout] of several capsules or [[capsule]] tables, not both");
  EXPECT_EQ(refusal("[layout]\ncount = 2\n"), "s.toml:2: layout.count: 2 capsules at one place: give their step layout.dx, dy or dz");
  EXPECT_EQ(refusal("[layout]\ncount = 2\ndx = 3\n[fluid]\nviscosity_ratio = 5\n"),
            "s.toml:5: fluid.viscosity_ratio: must be 1 with several capsules (the double layer over several surfaces is "
            "not implemented)");
  EXPECT_EQ(refusal("[time]\nstop_at_steady = true\n[[capsule]]\ncenter = [0, 0, 0]\n[[capsule]]\ncenter = [3, 0, 0]\n"),
            "s.toml:2: time.stop_at_steady: several capsules have no steady-state test: set time.t_end instead");
  // One capsule keeps everything it had.
  EXPECT_EQ(refusal("[fluid]\nviscosity_ratio = 5\n[time]\nstop_at_steady = true\n[[capsule]]\ncenter = [0, 0, 1]\n"),
            "(accepted)");
  EXPECT_NE(refusal("[contact]\nrepulsion_range = 4\n").find("contact.repulsion_range: 4 is out of range: must be in [0, 3]"),
            std::string::npos);
}

}  // namespace
}  // namespace capsflow
