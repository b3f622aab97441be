// Scene parsing: defaults, shipped scenes, overrides, and one test per error class
// (syntax, unknown key/section, wrong type, out of range, inconsistent keys).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

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

// time.tolerance: "auto" by default (the time plan chooses it, stepping/time_plan.hpp), a number
// turns it off, and either survives the resolved TOML of a checkpoint.
TEST(Scene, TimeToleranceIsAutoOrANumber) {
  const Scene d = parse_scene("", "d");
  EXPECT_TRUE(d.time.tolerance_auto);
  EXPECT_NE(to_toml(d).find("tolerance = \"auto\""), std::string::npos);
  EXPECT_TRUE(parse_scene(to_toml(d), "resolved").time.tolerance_auto);
  const Scene n = parse_scene("", "d", {"time.tolerance=1e-6"});
  EXPECT_FALSE(n.time.tolerance_auto);
  EXPECT_EQ(n.time.tolerance, 1e-6);
  const Scene r = parse_scene(to_toml(n), "resolved");
  EXPECT_FALSE(r.time.tolerance_auto);
  EXPECT_EQ(r.time.tolerance, 1e-6);
  EXPECT_TRUE(parse_scene("[time]\ntolerance = \"auto\"\n", "d").time.tolerance_auto);
}

TEST(Scene, OverridesApplyAndAreNamedInErrors) {
  const Scene s = parse_scene(default_scene_toml(), "d", {"mesh.level=2", "wall.law=nh", "output.fields=[\"energy\"]"});
  EXPECT_EQ(s.mesh.level, 2);
  EXPECT_EQ(s.wall.law, shell::LawKind::NeoHookean);
  EXPECT_TRUE(s.wants_field(OutputField::Energy));
  EXPECT_NE(error_of(default_scene_toml(), {"mesh.level=99"}).find("--set mesh.level"), std::string::npos);
  EXPECT_NE(error_of(default_scene_toml(), {"level=3"}).find("section.key"), std::string::npos);
}

TEST(SceneErrors, OverridesThatTomlWouldReadAsSomethingElseAreRefusedInOneLineNamingTheKey) {
  const auto one_line = [](const std::string& e) { return !e.empty() && e.find('\n') == std::string::npos; };
  // A line break in the value ended it there; the rest was read as a second line of TOML.
  const std::string nl = error_of(default_scene_toml(), {"time.t_end=1\nmesh.level=1"});
  EXPECT_NE(nl.find("--set time.t_end: the value 1\\nmesh.level=1 has a line break: one key per --set"), std::string::npos) << nl;
  EXPECT_TRUE(one_line(nl)) << nl;
  // '#' starts a TOML comment: `0.5#=2` was read as 0.5 (what Scene.set('time.t_end=0.5#', 2) sent).
  const std::string hash = error_of(default_scene_toml(), {"time.t_end=0.5#=2"});
  EXPECT_NE(hash.find("--set time.t_end: the value 0.5#=2 has a '#', which TOML reads as the start of a comment"),
            std::string::npos) << hash;
  // ... but a '#' inside a quoted string is the string's (then refused for its type, as a string).
  const std::string quoted = error_of(default_scene_toml(), {"time.t_end=\"0.5#\""});
  EXPECT_NE(quoted.find("--set time.t_end: expected"), std::string::npos) << quoted;
  EXPECT_NE(quoted.find("got a string"), std::string::npos) << quoted;
  // Keys with '#' or a line break are no keys; the echo is escaped, the message one line.
  for (const std::string bad : {"time.t_end#x=1", "time.t\nend=1"}) {
    const std::string e = error_of(default_scene_toml(), {bad});
    EXPECT_NE(e.find("key must be section.key"), std::string::npos) << e;
    EXPECT_TRUE(one_line(e)) << e;
  }
  EXPECT_NE(error_of(default_scene_toml(), {"time.t\nend=1"}).find("--set time.t\\nend=1"), std::string::npos);
  // An integer TOML cannot hold was taken as a string: "expected an integer, got a string".
  const std::string big = error_of(default_scene_toml(), {"mesh.level=1234567890123456789012345678901"});
  EXPECT_NE(big.find("--set mesh.level: 1234567890123456789012345678901 is out of range: integers have at most 64 bits"),
            std::string::npos) << big;
  EXPECT_NE(error_of(default_scene_toml(), {"time.t_end=-1_000_000_000_000_000_000_000"}).find("is out of range"),
            std::string::npos);
  // What was accepted before still is: unquoted strings, '#' in a string, the largest integer.
  EXPECT_EQ(parse_scene(default_scene_toml(), "d", {"wall.law=nh"}).wall.law, shell::LawKind::NeoHookean);
  EXPECT_NE(error_of(default_scene_toml(), {"fluid.verify_every=9223372036854775807"}).find("is out of range: must be in"),
            std::string::npos);  // held by TOML, then refused by the key's own range
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
  EXPECT_NE(error_of("[mesh]\nlevel = 12\n").find("mesh.level: 12 is out of range"), std::string::npos);
  EXPECT_NE(error_of("[wall]\nthickness = -0.1\n").find("wall.thickness"), std::string::npos);
  EXPECT_NE(error_of("[time]\nt_end = 0\n").find("time.t_end"), std::string::npos);
  EXPECT_NE(error_of("[flow]\nca_s = nan\n").find("flow.ca_s: must be finite"), std::string::npos);
  EXPECT_NE(error_of("[fluid]\nbackend = \"gpu\"\n").find("'gpu' is not one of"), std::string::npos);
  EXPECT_NE(error_of("[fluid]\ngeometry = \"bent\"\n").find("'bent' is not one of"), std::string::npos);
  EXPECT_NE(error_of("[fluid]\ntolerance = 1e-9\n").find("fluid.tolerance: 1e-9 is out of range: must be in [1e-8"),
            std::string::npos);
  EXPECT_NE(error_of("[output]\nfields = [\"stress\"]\n").find("output.fields"), std::string::npos);
  EXPECT_NE(error_of("[wall]\nlaw = \"mr\"\nmooney_rivlin_psi = 1.5\n").find("wall.mooney_rivlin_psi: 1.5 is out of range: must be in [0, 1]"),
            std::string::npos);
  EXPECT_NE(error_of("[wall]\nlaw = \"ogden\"\n").find("'ogden' is not one of: gh, nh, skalak, mr"), std::string::npos);
}

TEST(Scene, MooneyRivlinIsSelectableWithItsParameter) {
  const Scene s = parse_scene("[wall]\nlaw = \"mr\"\nmooney_rivlin_psi = 0.25\n", "test");
  EXPECT_EQ(s.wall.law, shell::LawKind::MooneyRivlin);
  EXPECT_EQ(s.wall.mooney_rivlin_psi, 0.25);  // exact: parsed from the text
  EXPECT_EQ(parse_scene(to_toml(s), "round trip").wall.mooney_rivlin_psi, 0.25);  // exact: shortest round-trip print
}

// fluid.verify_every and fluid.fmm_order: non-negative integers, one line naming the key.
TEST(SceneErrors, VerifyEveryAndFmmOrderAreCheckedAndNamed) {
  const Scene s = parse_scene(default_scene_toml(), "d", {"fluid.verify_every=25", "fluid.fmm_order=6"});
  EXPECT_EQ(s.fluid.verify_every, 25);
  EXPECT_EQ(s.fluid.fmm_order, 6);
  EXPECT_EQ(parse_scene(default_scene_toml(), "d").fluid.verify_every, 0);  // off by default
  EXPECT_EQ(parse_scene(to_toml(s), "resolved").fluid.verify_every, 25);    // kept in checkpoints' scene
  const std::string neg = error_of("[fluid]\nverify_every = -1\n");
  EXPECT_NE(neg.find("s.toml:2: fluid.verify_every: -1 is out of range: must be in [0, 1000000]"), std::string::npos) << neg;
  EXPECT_EQ(neg.find('\n'), std::string::npos) << neg;  // one line
  EXPECT_NE(error_of("[fluid]\nverify_every = 2.5\n").find("fluid.verify_every: expected an integer"), std::string::npos);
  EXPECT_NE(error_of(default_scene_toml(), {"fluid.verify_every=often"}).find("--set fluid.verify_every: expected an integer"),
            std::string::npos);
  EXPECT_NE(error_of("[fluid]\nfmm_order = 3\n").find("fluid.fmm_order: 3 is out of range: must be 0 or in [4, 14]"),
            std::string::npos);
}

// Every out-of-range message names what the user gave and the accepted range, in one
// form ("VALUE is out of range: must be RANGE (why)"); "verify_every out of range" said neither.
TEST(SceneErrors, OutOfRangeNamesTheValueAndTheRange) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"[mesh]\naxis = 4\n", "s.toml:2: mesh.axis: 4 is out of range: must be in [1, 3]"},
      {"[mesh]\naspect = 20\n", "mesh.aspect: 20 is out of range: must be in [0.1, 10]"},
      {"[wall]\nthickness = 0\n", "wall.thickness: 0 is out of range: must be in (0, 0.5] (h/ℓ)"},
      {"[wall]\npoisson = 1\n", "wall.poisson: 1 is out of range: must be in (-1, 1)"},
      {"[wall]\nskalak_c = -2\n", "wall.skalak_c: -2 is out of range: must be > 0"},
      {"[wall]\nmax_newton = 0\n", "wall.max_newton: 0 is out of range: must be in [1, 1000]"},
      {"[flow]\nca_v = -0.5\n", "flow.ca_v: -0.5 is out of range: must be > 0"},
      {"[time]\ntolerance = 1\n", "time.tolerance: 1 is out of range: must be in [1e-9, 0.1] (units of ℓ)"},
      {"[time]\ntolerance = \"loose\"\n", "time.tolerance: expected a number in [1e-9, 0.1] or \"auto\""},
      {"[time]\ndt = -1e-3\n", "time.dt: -0.001 is out of range: must be > 0"},
      {"[time]\nt_end = -5\n", "time.t_end: -5 is out of range: must be > 0"},
      {"[time]\nsteady_tol = 0\n", "time.steady_tol: 0 is out of range: must be > 0"},
      {"[output]\ncheckpoint_every = -1\n", "output.checkpoint_every: -1 is out of range: must be ≥ 0"},
      // An integer beyond int: refused with the range, not wrapped around.
      {"[fluid]\nverify_every = 10000000000\n", "fluid.verify_every: 10000000000 is out of range: must be in [0, 1000000]"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string e = error_of(text);
    EXPECT_NE(e.find(expected), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;  // one line
  }
  // On the command line the value is named the same way.
  const std::string set = error_of("", {"time.dt_safety=0.9"});
  EXPECT_EQ(set.rfind("--set time.dt_safety: 0.9 is out of range: must be in [0.001, 0.8] (0.8: the largest", 0), 0u) << set;
}

// fluid.viscosity_ratio: λ > 0 and finite; the message names the value and the range.
TEST(SceneErrors, ViscosityRatioOutsideItsRangeIsRefused) {
  for (const char* v : {"0", "-1", "1e-7", "2e6"}) {
    const std::string e = error_of(std::string("[fluid]\nviscosity_ratio = ") + v + "\n");
    EXPECT_NE(e.find(std::string("fluid.viscosity_ratio: ") + v + " is out of range: must be in [1e-6, 1e6]"), std::string::npos) << e;
  }
  for (const char* v : {"nan", "inf", "-inf"}) {  // not a number to print: finiteness, then the range
    const std::string e = error_of(std::string("[fluid]\nviscosity_ratio = ") + v + "\n");
    EXPECT_NE(e.find("fluid.viscosity_ratio: must be finite and in [1e-6, 1e6]"), std::string::npos) << v << ": " << e;
  }
  EXPECT_NE(error_of("", {"fluid.viscosity_ratio=0"}).find("--set fluid.viscosity_ratio: 0 is out of range"), std::string::npos);
  EXPECT_EQ(parse_scene(default_scene_toml(), "d").fluid.viscosity_ratio, 1.0);  // default: today's path
  EXPECT_EQ(parse_scene("[fluid]\nviscosity_ratio = 0.2\n", "s").fluid.viscosity_ratio, 0.2);
  EXPECT_NE(error_of("[fluid]\nmax_gmres = 0\n").find("fluid.max_gmres: 0 is out of range: must be in [1, 10000]"), std::string::npos);
}

TEST(SceneErrors, InconsistentKeys) {
  EXPECT_NE(error_of("[flow]\nca_s = 0.1\nca_v = 0.003\n").find("either flow.ca_s or flow.ca_v"), std::string::npos);
  EXPECT_NE(error_of("[flow]\ntype = \"linear\"\n").find("flow.gradient: required"), std::string::npos);
  EXPECT_NE(error_of("[flow]\ntype = \"linear\"\ngradient = [[1,0,0],[0,1,0],[0,0,1]]\n").find("trace-free"), std::string::npos);
  EXPECT_NE(error_of("[flow]\ngradient = [[0,1,0],[0,0,0],[0,0,0]]\n").find("only used with"), std::string::npos);
}

namespace {
std::string load_error(const std::string& path, const std::vector<std::string>& overrides = {}) {
  try {
    load_scene(path, overrides);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}
struct SceneDir {
  std::filesystem::path path = std::filesystem::temp_directory_path() /
                               ("capsflow-scene-" + std::to_string(::getpid()) + "-" +
                                ::testing::UnitTest::GetInstance()->current_test_info()->name());
  SceneDir() { std::filesystem::create_directories(path); }
  ~SceneDir() { std::filesystem::remove_all(path); }
  std::string file(const std::string& name, const std::string& text) const {
    std::ofstream(path / name, std::ios::binary) << text;
    return (path / name).string();
  }
};
}  // namespace

TEST(SceneErrors, OverrideOfAnUnknownSectionNamesTheOverride) {
  // Once "<built-in default>: foo: unknown section": the file was blamed for the command line.
  const std::string e = error_of(default_scene_toml(), {"foo.bar=1"});
  EXPECT_EQ(e.rfind("--set foo.bar: unknown section [foo]", 0), 0u) << e;
  // A section that is in the file is still reported at its line.
  EXPECT_NE(error_of("[foo]\nx = 1\n", {"foo.y=2"}).find("s.toml:1: foo: unknown section"), std::string::npos);
}

TEST(SceneFiles, MissingFolderUnreadableAndBinaryFilesAreTold) {
  SceneDir d;
  const std::string missing = load_error((d.path / "nope.toml").string());
  EXPECT_NE(missing.find("nope.toml: scene file not found"), std::string::npos) << missing;
  // A folder was read as an empty scene: the run went ahead with the defaults.
  const std::string folder = load_error(d.path.string());
  EXPECT_NE(folder.find("is a folder, not a scene file"), std::string::npos) << folder;
  // A checkpoint passed as a scene was "invalid UTF-8".
  const std::string h5 = load_error(d.file("checkpoint.h5", std::string("\x89HDF\r\n\x1a\n", 8) + std::string(64, '\0')));
  EXPECT_NE(h5.find("is an HDF5 file (a checkpoint?), not a TOML scene; to continue a run use: capsflow run --restart"),
            std::string::npos) << h5;
  EXPECT_NE(load_error(d.file("blob.toml", std::string("[mesh]\0\1", 8))).find("is a binary file"), std::string::npos);
  // Unreadable: /proc/sys/vm/drop_caches is write-only even for root (tests run as root in CI).
  const std::string wo = "/proc/sys/vm/drop_caches";
  if (std::filesystem::exists(wo)) {
    const std::string e = load_error(wo);
    EXPECT_NE(e.find("cannot read scene file: "), std::string::npos) << e;
    EXPECT_EQ(e.find("not found"), std::string::npos) << e;
  }
}

// A FIFO given as a scene blocks in open() for ever; a device read for ever.
TEST(SceneFiles, AFifoOrADeviceIsRefusedWithoutBlocking) {
  SceneDir d;
  const std::string fifo = (d.path / "scene.toml").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(load_error(fifo).find("is a FIFO, not a regular file"), std::string::npos) << load_error(fifo);
  EXPECT_NE(load_error("/dev/zero").find("is a character device, not a regular file"), std::string::npos);
}

TEST(SceneFiles, MeshFileIsRelativeToTheScenesFolder) {
  SceneDir d;
  std::filesystem::create_directories(d.path / "scenes" / "meshes");
  const std::string scene = d.file("scenes/capsule.toml", "[mesh]\nfile = \"meshes/cell.off\"\n");
  EXPECT_EQ(load_scene(scene).mesh.file, (d.path / "scenes" / "meshes" / "cell.off").string());
  // From the command line a path is relative to the working directory, like any argument.
  EXPECT_EQ(load_scene(scene, {"mesh.file=here.off"}).mesh.file, "here.off");
  const std::string abs = d.file("scenes/abs.toml", "[mesh]\nfile = \"/data/cell.off\"\n");
  EXPECT_EQ(load_scene(abs).mesh.file, "/data/cell.off");
}

TEST(Scene, CapillaryNoteWhenCaSFollowsFromCaV) {
  // The default scene gives ca_v: Ca_s = 0.003/α moves with wall.thickness.
  const Scene thick = parse_scene(default_scene_toml(), "d", {"wall.thickness=0.06"});
  EXPECT_NEAR(thick.flow.ca_s, 0.05, 1e-15);  // 0.003/0.06, one rounding
  const std::string note = capillary_note(thick);
  EXPECT_NE(note.find("Ca_s = 0.05 follows from flow.ca_v = 0.003 and wall.thickness = 0.06"), std::string::npos) << note;
  EXPECT_NE(note.find("give flow.ca_s"), std::string::npos) << note;
  EXPECT_EQ(capillary_note(parse_scene(default_scene_toml(), "d", {"flow.ca_s=0.1"})), "");
  EXPECT_NE(capillary_note(parse_scene("", "empty")), "");  // neither given: the default ca_v applies
}

// A 5 MB value was echoed whole in its one-line error. Values, keys and --set
// assignments are now cut to their first bytes, an ellipsis and their length.
TEST(SceneErrors, LongValuesAreAbbreviated) {
  const std::string huge(5 << 20, 'x');
  const std::string cases[] = {
      error_of("[fluid]\nbackend = \"" + huge + "\"\n"),          // a choice
      error_of("", {"fluid.backend=" + huge}),                     // the same on the command line
      error_of("", {"output.fields=[\"" + huge + "\"]"}),          // a list of choices
      error_of("[mesh]\n" + huge + " = 1\n"),                      // an unknown key
      error_of("", {"mesh." + huge + "=1"}),                       // an unknown key on the command line
      error_of("", {huge}),                                        // an assignment without '='
  };
  for (const std::string& e : cases) {
    EXPECT_LT(e.size(), 400u) << e.substr(0, 400);  // the message around it is < 200 bytes
    EXPECT_NE(e.find("… (52428"), std::string::npos) << e.substr(0, 400);  // the length: 5 MB and the key's "mesh." or "="
  }
  EXPECT_NE(cases[0].find("'xxxx"), std::string::npos) << cases[0].substr(0, 400);  // the start is kept
}

// Flow.ca_s = 1e-300 was accepted and the run ended with "mass-matrix CG stopped at its
// iteration cap (... relative residual -nan)". Ca_s, given or derived from ca_v and the thickness,
// must lie in [1e-6, 1e6] (scene_keys.cpp: capillary_range, with the reason).
TEST(SceneErrors, CapillaryNumberOutsideAMillionEitherWayIsRefused) {
  const std::string tiny = error_of("", {"flow.ca_s=1e-300"});
  EXPECT_EQ(tiny.rfind("--set flow.ca_s: 1e-300 is out of range: must be in [1e-6, 1e6] (Ca_s = μγ̇ℓ/G_s", 0), 0u) << tiny;
  EXPECT_NE(error_of("[flow]\nca_s = 2e6\n").find("s.toml:2: flow.ca_s: 2e6 is out of range"), std::string::npos);
  // Derived from ca_v: the message names both inputs and the Ca_s they give, at the key given.
  const std::string cav = error_of("[flow]\nca_v = 1e-300\n");
  EXPECT_NE(cav.find("s.toml:2: flow.ca_v: ca_v = 1e-300 and thickness = 0.03 give Ca_s = ca_v/thickness = 3.3333"),
            std::string::npos) << cav;
  EXPECT_NE(cav.find("out of range: must be in [1e-6, 1e6]"), std::string::npos) << cav;
  // Only the thickness given: the default ca_v = 0.003 with thickness 1e-12 gives Ca_s = 3e9.
  const std::string thin = error_of("[wall]\nthickness = 1e-12\n");
  EXPECT_NE(thin.find("s.toml:2: wall.thickness: ca_v = 0.003 and thickness = 1e-12 give Ca_s"), std::string::npos) << thin;
  // The ends themselves are accepted (closed range).
  EXPECT_EQ(parse_scene("", "d", {"flow.ca_s=1e-6"}).flow.ca_s, 1e-6);
  EXPECT_EQ(parse_scene("", "d", {"flow.ca_s=1e6"}).flow.ca_s, 1e6);
}

// Fluid.fmm_order was silently ignored when the far field is summed directly. The note
// says so whenever an order is forced and the back end used is the direct sum (asked for, or
// chosen by "auto" for a small mesh); it is a warning, not an error (docs §2.6).
TEST(Scene, AForcedFmmOrderUnusedByTheDirectSumIsNoted) {
  const Scene forced = parse_scene("", "d", {"fluid.fmm_order=8", "fluid.backend=direct"});
  const std::string note = unused_fmm_order_note(forced, FarFieldBackend::Direct);
  EXPECT_NE(note.find("fluid.fmm_order = 8 is not used: the far field is summed directly (fluid.backend = \"direct\")"),
            std::string::npos) << note;
  const Scene automatic = parse_scene("", "d", {"fluid.fmm_order=8"});
  EXPECT_NE(unused_fmm_order_note(automatic, FarFieldBackend::Direct).find("(fluid.backend = \"auto\")"), std::string::npos);
  EXPECT_EQ(unused_fmm_order_note(automatic, FarFieldBackend::Fmm), "");           // the FMM uses it
  EXPECT_EQ(unused_fmm_order_note(parse_scene("", "d"), FarFieldBackend::Direct), "");  // nothing forced
}

// Time.dt = 1e-300 or output.every = 1e-300 was accepted and would have needed ~1e300
// steps or outputs (ETA "?"). Counts to time.t_end are bounded (1e9 steps, 1e7 outputs or
// checkpoints: scene_rules.hpp) and the message gives the count and the smallest interval allowed.
TEST(SceneErrors, StepOutputAndCheckpointCountsAreBounded) {
  const std::string dt = error_of("", {"time.dt=1e-300"});  // t_end = 5 by default
  EXPECT_EQ(dt, "--set time.dt: 1e-300 would need 5e300 steps to time.t_end = 5; at most 1e9 are allowed (time.dt ≥ 5e-9)");
  const std::string every = error_of("[output]\nevery = 1e-300\n");
  EXPECT_NE(every.find("s.toml:2: output.every: 1e-300 would need 5e300 outputs to time.t_end = 5; at most 1e7 are allowed "
                       "(output.every ≥ 5e-7)"),
            std::string::npos) << every;
  EXPECT_NE(error_of("", {"output.checkpoint_every=1e-300"}).find("would need 5e300 checkpoints"), std::string::npos);
  // A huge t_end is caught by the same counts, at the interval it multiplies.
  EXPECT_NE(error_of("", {"time.t_end=1e300"}).find("output.every: 0.1 would need 1e301 outputs to time.t_end = 1e300"),
            std::string::npos);
  EXPECT_NE(error_of("", {"time.t_end=1e308"}).find("output.every: 0.1 would need more than 1e308 outputs"), std::string::npos);
  // The bounds themselves are accepted; an automatic step and checkpoint_every = 0 are not counted.
  EXPECT_NO_THROW(parse_scene("", "d", {"time.t_end=1", "time.dt=1e-9", "output.every=1e-7", "output.checkpoint_every=1e-7"}));
  EXPECT_NO_THROW(parse_scene("", "d", {"time.t_end=1e5", "output.every=0.01", "output.checkpoint_every=0"}));
}

// Output.fields with 200 000 duplicates was stored verbatim (a 4 MB summary.json).
// Lists of choices fold a repeated name into its first place (not refused: a restart must read
// any list a checkpoint stored).
TEST(Scene, RepeatedNamesInAListCountOnce) {
  std::string many;
  for (int i = 0; i < 200000; ++i) many += "\"energy\", ";
  const Scene s = parse_scene("[output]\nfields = [\"velocity\", " + many + "\"load\", \"velocity\"]\n", "s.toml");
  EXPECT_EQ(s.output.fields, (std::vector<OutputField>{OutputField::Velocity, OutputField::Energy, OutputField::Load}));
  EXPECT_NE(to_toml(s).find("fields = [\"velocity\", \"energy\", \"load\"]\n"), std::string::npos) << to_toml(s);
  const Scene t = parse_scene("", "d", {"time.stop_on=[\"element_quality\", \"element_quality\"]"});
  EXPECT_EQ(t.time.stop_on, std::vector<HealthCondition>{HealthCondition::ElementQuality});
}

// Time.dt_safety = 1e-300 was accepted: Heun's automatic step would have been 1e-300 of
// the stable one, a step count no bound on time.dt can see. 1e-3 (700× the default's steps) is the
// smallest fraction accepted.
TEST(SceneErrors, AVanishingSafetyFactorIsRefused) {
  EXPECT_EQ(error_of("", {"time.dt_safety=1e-300"}),
            "--set time.dt_safety: 1e-300 is out of range: must be in [0.001, 0.8] (0.8: the largest fraction of the "
            "calibrated limit measured stable)");
  EXPECT_EQ(parse_scene("", "d", {"time.dt_safety=1e-3"}).time.dt_safety, 1e-3);  // the end itself
}

// (5 MB values) a mesh.file longer than a path can be is refused when the scene is read,
// abbreviated, before the mesh reader would echo it.
TEST(SceneErrors, AMeshPathLongerThanAPathCanBeIsRefused) {
  const std::string e = error_of("", {"mesh.file=" + std::string(5 << 20, 'm') + ".off"});
  EXPECT_EQ(e.rfind("--set mesh.file: 'mmm", 0), 0u) << e.substr(0, 200);
  EXPECT_NE(e.find("… (5242884 bytes)' is longer than a path can be (4095 bytes)"), std::string::npos) << e.substr(0, 200);
  EXPECT_LT(e.size(), 200u);
  EXPECT_EQ(parse_scene("", "d", {"mesh.file=" + std::string(4091, 'm') + ".off"}).mesh.file.size(), 4095u);  // the longest
}
