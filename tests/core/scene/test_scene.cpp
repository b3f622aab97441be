// Scene parsing: defaults, shipped scenes, overrides, and one test per error class
// (syntax, unknown key/section, wrong type, out of range, inconsistent keys).
#include <gtest/gtest.h>

#include <filesystem>

#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/geometry/taylor_deformation.hpp"
#include "capsflow/core/scene/scene.hpp"

using namespace capsflow;

namespace {
std::string error_of(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    parse_scene(text, "s.toml", overrides);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Scene, BuiltInDefaultResolves) {
  const Scene s = parse_scene(default_scene_toml(), "default");
  EXPECT_EQ(s.mesh.level, 3);
  EXPECT_EQ(s.wall.model, WallModel::Gsmb);
  EXPECT_DOUBLE_EQ(s.flow.ca_v, 0.003);
  EXPECT_NEAR(s.flow.ca_s, 0.1, 1e-15);  // Ca_s = Ca_v/α (paper Eq. 37), one rounding
  EXPECT_TRUE(s.time.dt_auto);
  // Planar hyperbolic: L = diag(1, 0, −1) (paper Eq. 39).
  EXPECT_EQ(s.flow.gradient, (Mat3() << 1, 0, 0, 0, 0, 0, 0, 0, -1).finished());
}

TEST(Scene, ShippedScenesParseAndQuickEqualsDefault) {
  const std::filesystem::path dir = std::filesystem::path(CAPSFLOW_SOURCE_DIR) / "scenes";
  int n = 0;
  for (const auto& f : std::filesystem::directory_iterator(dir))
    if (f.path().extension() == ".toml") {
      EXPECT_NO_THROW(load_scene(f.path().string())) << f.path();
      ++n;
    }
  EXPECT_GE(n, 6);
  EXPECT_EQ(to_toml(load_scene((dir / "quick.toml").string())), to_toml(parse_scene(default_scene_toml(), "d")));
}

TEST(Scene, PaperCaseMesh) {
  const Scene s = load_scene(std::string(CAPSFLOW_SOURCE_DIR) + "/scenes/paper_fig4_gh_alpha3.toml");
  const SurfaceMesh m = make_reference_mesh(s.mesh);
  EXPECT_EQ(m.num_elements(), 5120);
  EXPECT_EQ(m.num_nodes(), 2562);
  EXPECT_NEAR(taylor_deformation(inertia_ellipsoid(m)).D13, -1.0 / 6, 1e-12);  // exact (docs/conventions.md §5.3)
}

TEST(Scene, ResolvedTomlRoundTrips) {
  const Scene a = parse_scene(default_scene_toml(), "d", {"flow.type=linear", "flow.gradient=[[0,1,0],[0,0,0],[0,0,0]]", "time.dt=1e-3"});
  const Scene b = parse_scene(to_toml(a), "resolved");
  EXPECT_EQ(to_toml(a), to_toml(b));
  EXPECT_FALSE(b.time.dt_auto);
  EXPECT_DOUBLE_EQ(b.time.dt, 1e-3);
  EXPECT_DOUBLE_EQ(b.flow.gradient(0, 1), 1.0);
}

TEST(Scene, OverridesApplyAndAreNamedInErrors) {
  const Scene s = parse_scene(default_scene_toml(), "d", {"mesh.level=2", "wall.law=nh", "output.fields=[\"energy\"]"});
  EXPECT_EQ(s.mesh.level, 2);
  EXPECT_EQ(s.wall.law, shell::LawKind::NeoHookean);
  EXPECT_TRUE(s.wants_field(OutputField::Energy));
  EXPECT_NE(error_of(default_scene_toml(), {"mesh.level=99"}).find("--set mesh.level"), std::string::npos);
  EXPECT_NE(error_of(default_scene_toml(), {"level=3"}).find("section.key"), std::string::npos);
}

TEST(SceneErrors, Syntax) {
  const std::string e = error_of("[mesh]\nlevel = = 3\n");
  EXPECT_EQ(e.rfind("s.toml:2:", 0), 0u) << e;  // file and line first
}

TEST(SceneErrors, UnknownKeyNamesKeyFileAndLine) {
  const std::string e = error_of("[mesh]\nlevel = 3\nlevle = 4\n");
  EXPECT_NE(e.find("s.toml:3: mesh.levle: unknown key"), std::string::npos) << e;
  const std::string s = error_of("[meshes]\nlevel = 3\n");
  EXPECT_NE(s.find("unknown section [meshes]"), std::string::npos) << s;
}

TEST(SceneErrors, WrongType) {
  const std::string e = error_of("[mesh]\nlevel = \"four\"\n");
  EXPECT_NE(e.find("s.toml:2: mesh.level: expected an integer, got a string"), std::string::npos) << e;
  EXPECT_NE(error_of("[time]\ndt = \"fast\"\n").find("time.dt"), std::string::npos);
  EXPECT_NE(error_of("[flow]\ntype = \"linear\"\ngradient = [1, 2, 3]\n").find("3×3"), std::string::npos);
}

TEST(SceneErrors, OutOfRange) {
  EXPECT_NE(error_of("[mesh]\nlevel = 12\n").find("mesh.level: 12 out of range"), std::string::npos);
  EXPECT_NE(error_of("[wall]\nthickness = -0.1\n").find("wall.thickness"), std::string::npos);
  EXPECT_NE(error_of("[time]\nt_end = 0\n").find("time.t_end"), std::string::npos);
  EXPECT_NE(error_of("[flow]\nca_s = nan\n").find("flow.ca_s: must be finite"), std::string::npos);
  EXPECT_NE(error_of("[fluid]\nbackend = \"gpu\"\n").find("'gpu' is not one of"), std::string::npos);
  EXPECT_NE(error_of("[fluid]\ngeometry = \"bent\"\n").find("'bent' is not one of"), std::string::npos);
  EXPECT_NE(error_of("[fluid]\ntolerance = 1e-9\n").find("fluid.tolerance: must be in [1e-8"), std::string::npos);
  EXPECT_NE(error_of("[output]\nfields = [\"stress\"]\n").find("output.fields"), std::string::npos);
}

TEST(SceneErrors, InconsistentKeys) {
  EXPECT_NE(error_of("[flow]\nca_s = 0.1\nca_v = 0.003\n").find("either flow.ca_s or flow.ca_v"), std::string::npos);
  EXPECT_NE(error_of("[flow]\ntype = \"linear\"\n").find("flow.gradient: required"), std::string::npos);
  EXPECT_NE(error_of("[flow]\ntype = \"linear\"\ngradient = [[1,0,0],[0,1,0],[0,0,1]]\n").find("trace-free"), std::string::npos);
  EXPECT_NE(error_of("[flow]\ngradient = [[0,1,0],[0,0,0],[0,0,0]]\n").find("only used with"), std::string::npos);
}
