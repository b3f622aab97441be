#include "capsflow/core/scene/scene.hpp"

#include "capsflow/core/io/input_file.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <toml++/toml.h>

#include "key_table.hpp"
#include "scene_rules.hpp"
#include "toml_reader.hpp"

namespace capsflow {

using namespace scene_detail;

namespace {

// Section → its keys, for the unknown-key check.
const std::map<std::string, std::set<std::string>>& known_keys() {
  static const auto known = [] {
    std::map<std::string, std::set<std::string>> m;
    for_each_section([&](const auto& sec) {
      for (const auto& k : sec.keys) m[sec.name].insert(k.name);
    });
    return m;
  }();
  return known;
}

// The key that a --set of `dotted` removes (ca_s and ca_v are alternatives), or "".
std::string alternative_of(const std::string& dotted) {
  std::string alt;
  for_each_section([&](const auto& sec) {
    for (const auto& k : sec.keys)
      if (!k.alternative.empty() && dotted == sec.name + "." + k.name) alt = k.alternative;
  });
  return alt;
}

std::string line_of(const std::string& name, const toml::node& n) {
  return n.source().begin.line > 0 ? name + ":" + std::to_string(n.source().begin.line) + ": " : name + ": ";
}

// The [[capsule]] array as given: each table's centre and its [mesh] and [wall] sub-tables (read
// against the scene's sections once those are known: read_capsule_sections). A wrong type, any other
// key or a count outside [1, 1000] is refused naming the capsule (1-based) and the key. The array
// leaves `root` (the key table's check knows only the sections).
struct RawCapsule {
  CapsuleSpec spec;
  const toml::table* table = nullptr;  // the capsule's table: its "mesh", "wall" sub-tables
  std::string where;                   // "s.toml:12: capsule 2: "
};

// `holder` takes the array out of `root` (the nodes keep their lines for the messages).
std::vector<RawCapsule> take_capsule_array(toml::table& root, toml::table& holder, const std::string& name) {
  std::vector<RawCapsule> out;
  if (!root.get("capsule")) return out;
  holder.insert("capsule", std::move(*root.get("capsule")));
  root.erase("capsule");
  toml::node* node = holder.get("capsule");
  const std::string at = line_of(name, *node);
  const toml::array* arr = node->as_array();
  if (arr && arr->empty()) throw SceneError(at + "capsule: an empty array: give one [[capsule]] table per capsule, or none");
  if (!arr || !arr->is_array_of_tables())
    throw SceneError(at + "capsule: expected an array of tables [[capsule]] (each with its center = [x, y, z])");
  if (arr->size() > static_cast<std::size_t>(kMaxCapsules))
    throw SceneError(fmt::format("{}capsule: {} [[capsule]] tables: at most {} capsules", at, arr->size(), kMaxCapsules));
  int k = 0;
  for (const toml::node& t : *arr) {
    ++k;
    RawCapsule c;
    c.table = t.as_table();
    c.where = line_of(name, t) + fmt::format("capsule {}: ", k);
    bool centered = false;
    for (const auto& [key, val] : *t.as_table()) {
      const std::string kname(key.str());
      if (kname == "mesh" || kname == "wall") {
        if (!val.is_table()) throw SceneError(c.where + kname + ": expected a table of " + kname + " keys");
        continue;
      }
      if (kname != "center")
        throw SceneError(c.where + "unknown key '" + kname + "' (known in [[capsule]]: center, and [capsule.mesh], [capsule.wall] tables)");
      const toml::array* v = val.as_array();
      bool ok = v && v->size() == 3;
      for (std::size_t i = 0; ok && i < 3; ++i) {
        const toml::node& e = *v->get(i);
        ok = e.is_number() && std::isfinite(e.value<double>().value_or(NAN));
        if (ok) c.spec.center[static_cast<Eigen::Index>(i)] = e.value<double>().value_or(0);
      }
      if (!ok) throw SceneError(c.where + "center: expected an array of 3 finite numbers [x, y, z]");
      centered = true;
    }
    if (!centered) throw SceneError(c.where + "center: required (the capsule's position [x, y, z], in ℓ)");
    out.push_back(std::move(c));
  }
  return out;
}

// A capsule's [mesh] and [wall] keys over the scene's sections, checked by the key table; a
// refusal names the capsule first.
void read_capsule_sections(const RawCapsule& raw, const Scene& scene, const std::string& name, CapsuleSpec& c) {
  const TomlReader r(*raw.table, name, {});
  const auto read = [&](const std::string& section, const auto& keys, auto spec) {
    std::set<std::string> known;
    for (const auto& k : keys) known.insert(k.name);
    for (const auto& [key, val] : *raw.table->get(section)->as_table())
      if (!known.count(std::string(key.str())))
        r.fail(section, std::string(key.str()),
               "unknown key (known in [" + section + "]: " + fmt::format("{}", fmt::join(known, ", ")) + ")");
    for (const auto& k : keys) k.read(r, section, spec);
    return spec;
  };
  try {
    if (raw.table->contains("mesh")) c.mesh = read("mesh", mesh_keys().keys, scene.mesh);
    if (raw.table->contains("wall")) c.wall = read("wall", wall_keys().keys, scene.wall);
  } catch (const SceneError& e) {  // "s.toml:14: wall.thickness: …" → "capsule 2: s.toml:14: wall.thickness: …"
    throw SceneError(raw.where.substr(raw.where.find("capsule ")) + e.what());
  }
}

// Plain "key=value" strings are --set's.
std::vector<SceneOverride> set_options(const std::vector<std::string>& assignments) {
  std::vector<SceneOverride> out;
  for (const std::string& a : assignments) out.push_back({a, "--set"});
  return out;
}

}  // namespace

Scene::Scene() { derive(*this); }

Scene Scene::capsule_scene(int k) const {
  Scene s = *this;
  if (k < static_cast<int>(capsules.size())) {
    const CapsuleSpec& c = capsules[static_cast<std::size_t>(k)];
    if (c.mesh) s.mesh = *c.mesh;
    if (c.wall) s.wall = *c.wall;
    derive(s);
  }
  return s;
}

bool Scene::capsules_alike() const {
  for (const CapsuleSpec& c : capsules)
    if (c.mesh || c.wall) return false;
  return true;
}

std::vector<Vec3> Scene::capsule_centers() const {
  std::vector<Vec3> out;
  for (const CapsuleSpec& c : capsules) out.push_back(c.center);
  if (!out.empty()) return out;
  const Vec3 step(layout.dx, layout.dy, layout.dz);
  for (int k = 0; k < layout.count; ++k) out.push_back((k - 0.5 * (layout.count - 1)) * step);
  return out;
}

bool Scene::wants_field(OutputField f) const {
  for (const auto& x : output.fields)
    if (x == f) return true;
  return false;
}

const std::string& default_scene_toml() {
  static const std::string s = R"(# capsflow built-in default scene: a quick, coarse version of the paper's case
# (Dupont et al. 2022, Fig. 4): prolate spheroid a/b = 1.4, GSMB wall with the generalized Hooke
# law, alpha = 3 %, Ca_v = 0.003, planar hyperbolic flow; 1280 elements.
[mesh]
base = "icosahedron"
level = 3
shape = "spheroid"
aspect = 1.4
axis = 3

[wall]
model = "gsmb"
law = "gh"
thickness = 0.03
poisson = 0.5

[flow]
type = "planar_hyperbolic"
ca_v = 0.003

[time]
dt = "auto"
t_end = 2.0

[fluid]
backend = "auto"
tolerance = "auto"

[output]
every = 0.1
checkpoint_every = 0.5
)";
  return s;
}

Scene parse_scene_with(const std::string& toml_text, const std::string& name, const std::vector<SceneOverride>& overrides) {
  toml::table root;
  try {
    root = toml::parse(toml_text, name);
  } catch (const toml::parse_error& e) {
    throw SceneError(name + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()));
  }
  std::map<std::string, std::string> overridden;  // key → the option that set it
  for (const SceneOverride& o : overrides) {
    const std::string key = apply_override(root, o.assignment, o.option);
    overridden[key] = o.option;
    // An alternative set on the command line replaces the other one (flow.ca_s ↔ flow.ca_v).
    if (const std::string alt = alternative_of(key); !alt.empty())
      if (toml::table* t = root.get(key.substr(0, key.find('.')))->as_table()) t->erase(alt);
  }
  Scene sc;
  toml::table capsule_array;
  const std::vector<RawCapsule> raw_capsules = take_capsule_array(root, capsule_array, name);
  const TomlReader r(root, name, overridden);
  r.check_known(known_keys());

  for_each_section([&](const auto& sec) {
    auto& spec = sc.*sec.member;
    for (const auto& k : sec.keys) k.read(r, sec.name, spec);
  });
  for (const RawCapsule& c : raw_capsules) {
    sc.capsules.push_back(c.spec);
    read_capsule_sections(c, sc, name, sc.capsules.back());
  }
  derive(sc);
  check_rules(r, sc);
  if (!sc.capsules.empty() && sc.layout.count > 1)
    r.fail("layout", "count", "give either a [layout] of several capsules or [[capsule]] tables, not both");
  sc.source = name;
  sc.toml_text = toml_text;
  return sc;
}

Scene parse_scene(const std::string& toml_text, const std::string& name, const std::vector<std::string>& overrides) {
  return parse_scene_with(toml_text, name, set_options(overrides));
}

namespace {

// The scene file's bytes, with errors that tell a missing file from an unreadable one.
std::string read_scene_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (st.type() == fs::file_type::not_found) throw SceneError(path + ": scene file not found");
  if (ec) throw SceneError(path + ": cannot access scene file: " + ec.message());
  if (fs::is_directory(st)) throw SceneError(path + ": is a folder, not a scene file");
  if (!fs::is_regular_file(st)) throw SceneError(path + ": " + io::input_file_problem(path, io::kMaxSceneBytes));  // open() of a FIFO blocks
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw SceneError(path + ": cannot read scene file: " + std::strerror(errno));
  std::string text;
  char buf[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      throw SceneError(path + ": cannot read scene file: " + std::strerror(err));
    }
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
    if (text.size() > io::kMaxSceneBytes) {
      ::close(fd);
      throw SceneError(path + ": is larger than 64 MB: not a scene file");
    }
  }
  ::close(fd);
  // An HDF5 file (a checkpoint or a run.h5) given where a scene belongs.
  if (text.compare(0, 8, std::string("\x89HDF\r\n\x1a\n", 8)) == 0)
    throw SceneError(path + ": is an HDF5 file (a checkpoint?), not a TOML scene; to continue a run use: capsflow run --restart " + path);
  if (text.find('\0') != std::string::npos) throw SceneError(path + ": is a binary file, not a TOML scene");
  return text;
}

}  // namespace

Scene load_scene_with(const std::string& path, const std::vector<SceneOverride>& overrides) {
  Scene sc = parse_scene_with(read_scene_file(path), path, overrides);
  // mesh.file in a scene is relative to the scene's folder (a scene and its mesh travel
  // together); given on the command line it is relative to the working directory, like any argument.
  bool file_overridden = false;
  for (const auto& o : overrides) file_overridden = file_overridden || o.assignment.rfind("mesh.file=", 0) == 0;
  const auto resolve = [&path](std::string& file) {
    if (!file.empty() && std::filesystem::path(file).is_relative())
      file = (std::filesystem::path(path).parent_path() / file).lexically_normal().string();
  };
  if (!file_overridden) {
    resolve(sc.mesh.file);
    for (CapsuleSpec& c : sc.capsules)  // a capsule's own mesh file too, like [mesh]'s
      if (c.mesh) resolve(c.mesh->file);
  }
  return sc;
}

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  return load_scene_with(path, set_options(overrides));
}

std::string capillary_note(const Scene& s) {
  if (!s.flow.ca_s_from_ca_v) return "";
  return fmt::format("Ca_s = {:g} follows from flow.ca_v = {:g} and wall.thickness = {:g} (Ca_s = Ca_v/thickness): "
                     "changing only the thickness changes Ca_s too; give flow.ca_s to keep it fixed",
                     s.flow.ca_s, s.flow.ca_v, s.wall.thickness);
}

std::string unused_fmm_order_note(const Scene& s, FarFieldBackend used) {
  if (s.fluid.fmm_order == 0 || used != FarFieldBackend::Direct) return "";
  return fmt::format("fluid.fmm_order = {} is not used: the far field is summed directly (fluid.backend = \"{}\"), "
                     "which has no expansion order",
                     s.fluid.fmm_order, to_string(s.fluid.backend));
}

nlohmann::json to_json(const Scene& s) {
  nlohmann::json j;
  for_each_section([&](const auto& sec) {
    for (const auto& k : sec.keys) j[sec.name][k.name] = k.to_json(s.*sec.member);
  });
  if (!s.capsules.empty()) {
    j["capsule"] = nlohmann::json::array();
    for (const CapsuleSpec& c : s.capsules) {
      nlohmann::json e = {{"center", {c.center[0], c.center[1], c.center[2]}}};
      if (c.mesh)
        for (const auto& k : mesh_keys().keys) e["mesh"][k.name] = k.to_json(*c.mesh);
      if (c.wall)
        for (const auto& k : wall_keys().keys) e["wall"][k.name] = k.to_json(*c.wall);
      j["capsule"].push_back(e);
    }
  }
  return j;
}

std::string to_toml(const Scene& s) {
  // Written from the table (not toml++'s printer) to keep the key order of docs/scene-and-output.md §2
  // and print numbers in their shortest round-trip form.
  std::string out;
  for_each_section([&](const auto& sec) {
    out += (out.empty() ? "[" : "\n[") + sec.name + "]\n";
    for (const auto& k : sec.keys)
      if (const std::optional<std::string> v = k.to_toml(s.*sec.member)) out += k.name + " = " + *v + "\n";
  });
  const auto section = [&out](const std::string& name, const auto& keys, const auto& spec) {
    out += "[capsule." + name + "]\n";
    for (const auto& k : keys)
      if (const std::optional<std::string> v = k.to_toml(spec)) out += k.name + " = " + *v + "\n";
  };
  for (const CapsuleSpec& c : s.capsules) {
    out += fmt::format("\n[[capsule]]\ncenter = [{}, {}, {}]\n", c.center[0], c.center[1], c.center[2]);
    if (c.mesh) section("mesh", mesh_keys().keys, *c.mesh);
    if (c.wall) section("wall", wall_keys().keys, *c.wall);
  }
  return out;
}

}  // namespace capsflow
