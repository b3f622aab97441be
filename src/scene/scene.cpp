#include "capsflow/core/scene/scene.hpp"

#include "capsflow/core/io/input_file.hpp"

#include <fmt/core.h>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string_view>
#include <toml++/toml.h>

namespace capsflow {

namespace {

const std::map<std::string, std::set<std::string>>& schema() {
  static const std::map<std::string, std::set<std::string>> s = {
      {"mesh", {"base", "level", "shape", "aspect", "axis", "file"}},
      {"wall", {"model", "law", "thickness", "poisson", "skalak_c", "mooney_rivlin_psi", "max_newton"}},
      {"flow", {"type", "ca_v", "ca_s", "gradient"}},
      {"time", {"scheme", "tolerance", "dt", "dt_safety", "t_end", "stop_at_steady", "steady_tol", "stop_on"}},
      {"fluid", {"backend", "tolerance", "geometry", "volume_correction", "fmm_order", "verify_every"}},
      {"output", {"every", "fields", "checkpoint_every"}},
  };
  return s;
}

std::string join(const std::set<std::string>& s) {
  std::string out;
  for (const auto& k : s) out += (out.empty() ? "" : ", ") + k;
  return out;
}

// Reads typed values from the parsed table with messages "file:line: key: problem".
class Reader {
 public:
  Reader(const toml::table& root, std::string name, std::set<std::string> overridden)
      : root_(root), name_(std::move(name)), overridden_(std::move(overridden)) {}

  [[noreturn]] void fail(const std::string& key, const toml::node* node, const std::string& what) const {
    throw SceneError(where(key, node) + what);
  }
  std::string where(const std::string& key, const toml::node* node) const {
    if (overridden_.count(key)) return "--set " + key + ": ";
    for (const auto& k : overridden_)  // a section that only an override created
      if (k.compare(0, key.size() + 1, key + ".") == 0 && !(node && node->source().begin.line > 0)) return "--set " + k + ": ";
    if (node && node->source().begin.line > 0)
      return name_ + ":" + std::to_string(node->source().begin.line) + ": " + key + ": ";
    return name_ + ": " + key + ": ";
  }
  const toml::node* find(const std::string& section, const std::string& key) const {
    const toml::node* sec = root_.get(section);
    if (!sec || !sec->is_table()) return nullptr;
    return sec->as_table()->get(key);
  }
  bool has(const std::string& section, const std::string& key) const { return find(section, key) != nullptr; }

  void get(const std::string& s, const std::string& k, std::string& out) const {
    if (auto* n = find(s, k)) {
      if (!n->is_string()) fail(s + "." + k, n, "expected a string, got " + type_name(*n));
      out = n->as_string()->get();
    }
  }
  void get(const std::string& s, const std::string& k, double& out) const {
    if (auto* n = find(s, k)) {
      if (n->is_integer()) out = static_cast<double>(n->as_integer()->get());
      else if (n->is_floating_point()) out = n->as_floating_point()->get();
      else fail(s + "." + k, n, "expected a number, got " + type_name(*n));
      if (!std::isfinite(out)) fail(s + "." + k, n, "must be finite");
    }
  }
  void get(const std::string& s, const std::string& k, int& out) const {
    if (auto* n = find(s, k)) {
      if (!n->is_integer()) fail(s + "." + k, n, "expected an integer, got " + type_name(*n));
      const int64_t v = n->as_integer()->get();
      if (v < -1000000 || v > 1000000) fail(s + "." + k, n, "integer out of range");
      out = static_cast<int>(v);
    }
  }
  void get(const std::string& s, const std::string& k, bool& out) const {
    if (auto* n = find(s, k)) {
      if (!n->is_boolean()) fail(s + "." + k, n, "expected true or false, got " + type_name(*n));
      out = n->as_boolean()->get();
    }
  }
  void get(const std::string& s, const std::string& k, std::vector<std::string>& out) const {
    if (auto* n = find(s, k)) {
      if (!n->is_array()) fail(s + "." + k, n, "expected an array of strings, got " + type_name(*n));
      out.clear();
      for (const auto& e : *n->as_array()) {
        if (!e.is_string()) fail(s + "." + k, n, "expected an array of strings");
        out.push_back(e.as_string()->get());
      }
    }
  }
  void get(const std::string& s, const std::string& k, Mat3& out) const {
    if (auto* n = find(s, k)) {
      const std::string msg = "expected a 3×3 array of numbers [[..],[..],[..]]";
      if (!n->is_array() || n->as_array()->size() != 3) fail(s + "." + k, n, msg);
      for (int i = 0; i < 3; ++i) {
        const toml::node& row = *n->as_array()->get(i);
        if (!row.is_array() || row.as_array()->size() != 3) fail(s + "." + k, n, msg);
        for (int j = 0; j < 3; ++j) {
          const toml::node& v = *row.as_array()->get(j);
          if (v.is_integer()) out(i, j) = static_cast<double>(v.as_integer()->get());
          else if (v.is_floating_point()) out(i, j) = v.as_floating_point()->get();
          else fail(s + "." + k, n, msg);
          if (!std::isfinite(out(i, j))) fail(s + "." + k, n, "entries must be finite");
        }
      }
    }
  }
  // Range and choice checks, reported at the key's location.
  void require(bool ok, const std::string& s, const std::string& k, const std::string& what) const {
    if (!ok) fail(s + "." + k, find(s, k), what);
  }
  // A named choice (scene/options.hpp): the string must be one of the enum's spellings.
  template <class E>
  void get_choice(const std::string& s, const std::string& k, E& out) const {
    if (!find(s, k)) return;
    std::string name;
    get(s, k, name);
    const std::optional<E> v = from_string<E>(name);
    if (!v) fail(s + "." + k, find(s, k), "'" + name + "' is not one of: " + name_list<E>());
    out = *v;
  }
  template <class E>
  void get_choices(const std::string& s, const std::string& k, std::vector<E>& out) const {
    std::vector<std::string> names;
    get(s, k, names);
    if (!find(s, k)) return;
    out.clear();
    for (const auto& name : names) {
      const std::optional<E> v = from_string<E>(name);
      if (!v) fail(s + "." + k, find(s, k), "'" + name + "' is not one of: " + name_list<E>());
      out.push_back(*v);
    }
  }

  static std::string type_name(const toml::node& n) {
    switch (n.type()) {
      case toml::node_type::string: return "a string";
      case toml::node_type::integer: return "an integer";
      case toml::node_type::floating_point: return "a float";
      case toml::node_type::boolean: return "a boolean";
      case toml::node_type::array: return "an array";
      case toml::node_type::table: return "a table";
      default: return "a date/time";
    }
  }

 private:
  const toml::table& root_;
  std::string name_;
  std::set<std::string> overridden_;
};

void check_unknown_keys(const toml::table& root, const Reader& r, const std::string& name) {
  for (const auto& [sec, node] : root) {
    const std::string s(sec.str());
    auto it = schema().find(s);
    if (it == schema().end()) {
      std::set<std::string> sections;
      for (const auto& [k, v] : schema()) sections.insert(k);
      throw SceneError(r.where(s, &node) + "unknown section [" + s + "] (known: " + join(sections) + ")");
    }
    if (!node.is_table()) throw SceneError(r.where(s, &node) + "expected a table [" + s + "]");
    for (const auto& [key, val] : *node.as_table()) {
      const std::string k(key.str());
      if (!it->second.count(k))
        throw SceneError(r.where(s + "." + k, &val) + "unknown key (known in [" + s + "]: " + join(it->second) + ")");
    }
  }
  (void)name;
}

// "a.b=value": value parsed as a TOML value when possible, otherwise taken as a string.
std::string apply_override(toml::table& root, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw SceneError("--set " + assignment + ": expected key.path=value");
  const std::string key = assignment.substr(0, eq), value = assignment.substr(eq + 1);
  const auto dot = key.find('.');
  if (dot == std::string::npos || key.find('.', dot + 1) != std::string::npos)
    throw SceneError("--set " + assignment + ": key must be section.key (e.g. time.t_end)");
  const std::string sec = key.substr(0, dot), leaf = key.substr(dot + 1);
  toml::node_view<toml::node> parsed;
  toml::table tmp;
  try {
    tmp = toml::parse("v = " + value);
  } catch (const toml::parse_error&) {
    tmp = toml::table{{"v", value}};
  }
  if (!root.contains(sec)) root.insert(sec, toml::table{});
  toml::table* t = root.get(sec)->as_table();
  if (!t) throw SceneError("--set " + assignment + ": [" + sec + "] is not a table");
  t->insert_or_assign(leaf, *tmp.get("v"));
  // ca_s and ca_v are alternatives: setting one on the command line replaces the other.
  if (sec == "flow" && (leaf == "ca_s" || leaf == "ca_v")) t->erase(leaf == "ca_s" ? "ca_v" : "ca_s");
  return key;
}

}  // namespace

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
tolerance = 1e-6

[output]
every = 0.1
checkpoint_every = 0.5
)";
  return s;
}

Scene parse_scene(const std::string& toml_text, const std::string& name, const std::vector<std::string>& overrides) {
  toml::table root;
  try {
    root = toml::parse(toml_text, name);
  } catch (const toml::parse_error& e) {
    throw SceneError(name + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()));
  }
  std::set<std::string> overridden;
  for (const auto& o : overrides) overridden.insert(apply_override(root, o));
  Reader r(root, name, overridden);
  check_unknown_keys(root, r, name);

  Scene sc;
  sc.source = name;
  sc.toml_text = toml_text;
  auto& m = sc.mesh;
  r.get_choice("mesh", "base", m.base);
  r.get("mesh", "level", m.level);
  r.require(m.level >= 0 && m.level <= 9, "mesh", "level", std::to_string(m.level) + " out of range [0, 9]");
  r.get_choice("mesh", "shape", m.shape);
  r.get("mesh", "aspect", m.aspect);
  r.require(m.aspect >= 0.1 && m.aspect <= 10, "mesh", "aspect", "must be in [0.1, 10]");
  r.get("mesh", "axis", m.axis);
  r.require(m.axis >= 1 && m.axis <= 3, "mesh", "axis", "must be 1, 2 or 3");
  r.get("mesh", "file", m.file);
  if (m.shape == MeshShape::Sphere) m.aspect = 1.0;

  auto& w = sc.wall;
  r.get_choice("wall", "model", w.model);
  {
    // Law names belong to shell::MembraneLaw.
    std::string law;
    r.get("wall", "law", law);
    if (r.has("wall", "law")) {
      const std::optional<shell::LawKind> kind = shell::law_from_name(law);
      if (!kind || law != shell::to_string(*kind))  // canonical names only
        r.fail("wall.law", r.find("wall", "law"), "'" + law + "' is not one of: gh, nh, skalak, mr");
      w.law = *kind;
    }
  }
  r.get("wall", "thickness", w.thickness);
  r.require(w.thickness > 0 && w.thickness <= 0.5, "wall", "thickness", "must be in (0, 0.5] (h/ℓ)");
  r.get("wall", "poisson", w.poisson);
  r.require(w.poisson > -1 && w.poisson < 1, "wall", "poisson", "must be in (-1, 1)");
  r.get("wall", "skalak_c", w.skalak_c);
  r.get("wall", "mooney_rivlin_psi", w.mooney_rivlin_psi);
  r.require(w.mooney_rivlin_psi >= 0 && w.mooney_rivlin_psi <= 1, "wall", "mooney_rivlin_psi", "must be in [0, 1]");
  r.get("wall", "max_newton", w.max_newton);
  r.require(w.max_newton >= 1 && w.max_newton <= 1000, "wall", "max_newton", "must be in [1, 1000]");
  r.require(w.skalak_c > 0, "wall", "skalak_c", "must be positive");

  auto& f = sc.flow;
  r.get_choice("flow", "type", f.type);
  const bool has_cav = r.has("flow", "ca_v"), has_cas = r.has("flow", "ca_s");
  if (has_cav && has_cas) r.fail("flow.ca_s", r.find("flow", "ca_s"), "give either flow.ca_s or flow.ca_v, not both");
  f.ca_s_from_ca_v = !has_cas;
  if (has_cas) {
    r.get("flow", "ca_s", f.ca_s);
    r.require(f.ca_s > 0, "flow", "ca_s", "must be positive");
    f.ca_v = f.ca_s * w.thickness;
  } else {
    r.get("flow", "ca_v", f.ca_v);
    r.require(f.ca_v > 0, "flow", "ca_v", "must be positive");
    f.ca_s = f.ca_v / w.thickness;
  }
  f.gradient.setZero();
  if (f.type == FlowType::Linear) {
    if (!r.has("flow", "gradient")) r.fail("flow.gradient", nullptr, "required when flow.type = \"linear\"");
    r.get("flow", "gradient", f.gradient);
    r.require(std::abs(f.gradient.trace()) <= 1e-12 * std::max(1.0, f.gradient.norm()), "flow", "gradient",
              "must be trace-free (incompressible flow)");
  } else {
    r.require(!r.has("flow", "gradient"), "flow", "gradient", "only used with flow.type = \"linear\"");
    if (f.type == FlowType::PlanarHyperbolic) f.gradient.diagonal() << 1, 0, -1;  // v∞ = x1 e1 − x3 e3 (paper Eq. 39)
    if (f.type == FlowType::SimpleShear) f.gradient(0, 1) = 1;                  // v∞ = x2 e1
  }

  auto& t = sc.time;
  TimeScheme requested = TimeScheme::Auto;
  r.get_choice("time", "scheme", requested);
  t.scheme_auto = requested == TimeScheme::Auto;
  t.scheme = !t.scheme_auto ? requested : sc.wall.model == WallModel::Gsmb ? TimeScheme::Rkc : TimeScheme::Heun;
  r.get("time", "tolerance", t.tolerance);
  r.require(t.tolerance >= 1e-9 && t.tolerance <= 1e-1, "time", "tolerance", "must be in [1e-9, 1e-1] (units of ℓ)");
  if (const toml::node* n = r.find("time", "dt")) {
    if (n->is_string()) {
      if (n->as_string()->get() != "auto") r.fail("time.dt", n, "expected a positive number or \"auto\"");
      t.dt_auto = true;
    } else {
      r.get("time", "dt", t.dt);
      r.require(t.dt > 0, "time", "dt", "must be positive");
      t.dt_auto = false;
    }
  }
  r.get("time", "dt_safety", t.dt_safety);
  // The calibrated limit is a measured bound with 18 % to spare on the worst calibration case
  // (c_m = 1.15 measured against 1.4 used, docs/time-integration.md §5.2.3): above 0.8 a step is
  // no longer known to be stable (dt_safety = 1.4 loses 3 % of the volume and half of D13).
  r.require(t.dt_safety > 0 && t.dt_safety <= 0.8, "time", "dt_safety",
            "must be in (0, 0.8] (the largest fraction of the calibrated limit measured stable)");
  r.get("time", "t_end", t.t_end);
  r.require(t.t_end > 0, "time", "t_end", "must be positive");
  r.get("time", "stop_at_steady", t.stop_at_steady);
  r.get("time", "steady_tol", t.steady_tol);
  r.require(t.steady_tol > 0, "time", "steady_tol", "must be positive");
  r.get_choices("time", "stop_on", t.stop_on);

  r.get_choice("fluid", "backend", sc.fluid.backend);
  r.get("fluid", "tolerance", sc.fluid.tolerance);
  r.get_choice("fluid", "geometry", sc.fluid.geometry);
  r.get("fluid", "volume_correction", sc.fluid.volume_correction);
  // The boundary integral asks the FMM for 0.25 × the tolerance (its floor is 1e-10,
  // fmm/calibration.hpp), and its direct far field is accurate to ~1e-9 (single_layer.cpp).
  r.require(sc.fluid.tolerance >= 1e-8 && sc.fluid.tolerance <= 1e-1, "fluid", "tolerance",
            "must be in [1e-8, 1e-1] (the far-field sums are accurate to ~1e-9)");
  r.get("fluid", "fmm_order", sc.fluid.fmm_order);
  // The calibrated orders (fmm/calibration.hpp); 0 keeps the order the tolerance calls for.
  r.require(sc.fluid.fmm_order == 0 || (sc.fluid.fmm_order >= 4 && sc.fluid.fmm_order <= 14), "fluid", "fmm_order",
            "must be 0 (from fluid.tolerance) or an FMM order in [4, 14]");
  r.get("fluid", "verify_every", sc.fluid.verify_every);
  r.require(sc.fluid.verify_every >= 0, "fluid", "verify_every",
            "must be a non-negative integer: right-hand-side evaluations between direct checks (0 = off)");

  auto& o = sc.output;
  r.get("output", "every", o.every);
  r.require(o.every > 0, "output", "every", "must be positive");
  r.get_choices("output", "fields", o.fields);
  r.get("output", "checkpoint_every", o.checkpoint_every);
  r.require(o.checkpoint_every >= 0, "output", "checkpoint_every", "must be >= 0 (0 disables)");
  return sc;
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

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  Scene sc = parse_scene(read_scene_file(path), path, overrides);
  // mesh.file in a scene is relative to the scene's folder (a scene and its mesh travel
  // together); given with --set it is relative to the working directory, like any argument.
  bool file_overridden = false;
  for (const auto& o : overrides) file_overridden = file_overridden || o.rfind("mesh.file=", 0) == 0;
  if (!sc.mesh.file.empty() && !file_overridden && std::filesystem::path(sc.mesh.file).is_relative())
    sc.mesh.file = (std::filesystem::path(path).parent_path() / sc.mesh.file).lexically_normal().string();
  return sc;
}

std::string capillary_note(const Scene& s) {
  if (!s.flow.ca_s_from_ca_v) return "";
  return fmt::format("Ca_s = {:g} follows from flow.ca_v = {:g} and wall.thickness = {:g} (Ca_s = Ca_v/thickness): "
                     "changing only the thickness changes Ca_s too; give flow.ca_s to keep it fixed",
                     s.flow.ca_s, s.flow.ca_v, s.wall.thickness);
}

nlohmann::json to_json(const Scene& s) {
  nlohmann::json g = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) g.push_back({s.flow.gradient(i, 0), s.flow.gradient(i, 1), s.flow.gradient(i, 2)});
  nlohmann::json j;
  std::vector<std::string> fields, stop_on;
  for (OutputField f : s.output.fields) fields.emplace_back(to_string(f));
  for (HealthCondition c : s.time.stop_on) stop_on.emplace_back(to_string(c));
  j["mesh"] = {{"base", to_string(s.mesh.base)}, {"level", s.mesh.level}, {"shape", to_string(s.mesh.shape)},
               {"aspect", s.mesh.aspect}, {"axis", s.mesh.axis}, {"file", s.mesh.file}};
  j["wall"] = {{"model", to_string(s.wall.model)}, {"law", shell::to_string(s.wall.law)}, {"thickness", s.wall.thickness},
               {"poisson", s.wall.poisson}, {"skalak_c", s.wall.skalak_c},
               {"mooney_rivlin_psi", s.wall.mooney_rivlin_psi}, {"max_newton", s.wall.max_newton}};
  j["flow"] = {{"type", to_string(s.flow.type)}, {"ca_s", s.flow.ca_s}, {"ca_v", s.flow.ca_v}, {"gradient", g}};
  j["time"] = {{"scheme", to_string(s.time.scheme)}, {"tolerance", s.time.tolerance},
               {"dt", s.time.dt_auto ? nlohmann::json("auto") : nlohmann::json(s.time.dt)},
               {"dt_safety", s.time.dt_safety}, {"t_end", s.time.t_end},
               {"stop_at_steady", s.time.stop_at_steady}, {"steady_tol", s.time.steady_tol}, {"stop_on", stop_on}};
  j["fluid"] = {{"backend", to_string(s.fluid.backend)}, {"tolerance", s.fluid.tolerance}, {"geometry", to_string(s.fluid.geometry)}, {"volume_correction", s.fluid.volume_correction},
                {"fmm_order", s.fluid.fmm_order}, {"verify_every", s.fluid.verify_every}};
  j["output"] = {{"every", s.output.every}, {"fields", fields}, {"checkpoint_every", s.output.checkpoint_every}};
  return j;
}

std::string to_toml(const Scene& s) {
  // Written by hand (not toml++'s printer) to keep the section order of docs/scene-and-output.md §2 and print
  // numbers in their shortest round-trip form.
  auto q = [](std::string_view v) { return fmt::format("\"{}\"", v); };
  std::string out;
  out += fmt::format("[mesh]\nbase = {}\nlevel = {}\nshape = {}\naspect = {}\naxis = {}\n", q(to_string(s.mesh.base)), s.mesh.level,
                     q(to_string(s.mesh.shape)), s.mesh.aspect, s.mesh.axis);
  if (!s.mesh.file.empty()) out += fmt::format("file = {}\n", q(s.mesh.file));
  out += fmt::format("\n[wall]\nmodel = {}\nlaw = {}\nthickness = {}\npoisson = {}\nskalak_c = {}\nmooney_rivlin_psi = {}\n"
                     "max_newton = {}\n",
                     q(to_string(s.wall.model)), q(shell::to_string(s.wall.law)), s.wall.thickness, s.wall.poisson,
                     s.wall.skalak_c, s.wall.mooney_rivlin_psi, s.wall.max_newton);
  out += fmt::format("\n[flow]\ntype = {}\nca_s = {}  # ca_v = ca_s * thickness = {}\n", q(to_string(s.flow.type)), s.flow.ca_s, s.flow.ca_v);
  if (s.flow.type == FlowType::Linear) {
    const Mat3& g = s.flow.gradient;
    out += fmt::format("gradient = [[{}, {}, {}], [{}, {}, {}], [{}, {}, {}]]\n", g(0, 0), g(0, 1), g(0, 2), g(1, 0), g(1, 1),
                       g(1, 2), g(2, 0), g(2, 1), g(2, 2));
  }
  out += fmt::format("\n[time]\nscheme = {}\ntolerance = {}\ndt = {}\ndt_safety = {}\nt_end = {}\nstop_at_steady = {}\nsteady_tol = {}\n",
                     q(to_string(s.time.scheme)), s.time.tolerance, s.time.dt_auto ? q("auto") : fmt::format("{}", s.time.dt), s.time.dt_safety, s.time.t_end,
                     s.time.stop_at_steady, s.time.steady_tol);
  std::string stop_on;
  for (HealthCondition c : s.time.stop_on) stop_on += (stop_on.empty() ? "" : ", ") + q(to_string(c));
  out += fmt::format("stop_on = [{}]\n", stop_on);
  out += fmt::format("\n[fluid]\nbackend = {}\ntolerance = {}\ngeometry = {}\nvolume_correction = {}\nfmm_order = {}\nverify_every = {}\n",
                     q(to_string(s.fluid.backend)), s.fluid.tolerance, q(to_string(s.fluid.geometry)), s.fluid.volume_correction,
                     s.fluid.fmm_order, s.fluid.verify_every);
  std::string fields;
  for (OutputField f : s.output.fields) fields += (fields.empty() ? "" : ", ") + q(to_string(f));
  out += fmt::format("\n[output]\nevery = {}\nfields = [{}]\ncheckpoint_every = {}\n", s.output.every, fields,
                     s.output.checkpoint_every);
  return out;
}

}  // namespace capsflow
