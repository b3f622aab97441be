#include "capsflow/core/mesh/mesh_io.hpp"

#include "capsflow/core/io/input_file.hpp"

#include <fmt/core.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <new>
#include <regex>
#include <sstream>
#include <vector>

namespace capsflow {

namespace {

std::string lower_ext(const std::string& path) {
  const auto dot = path.find_last_of('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw MeshError(path + ": " + what);
}

SurfaceMesh finish(SurfaceMesh mesh, const std::string& path) {
  try {
    validate_closed_surface(mesh);
  } catch (const MeshError& e) {
    fail(path, e.what());
  }
  return mesh;
}

// Line reader that skips blank lines and '#' comments and remembers the line number.
struct LineReader {
  std::istream& in;
  int line = 0;
  bool next(std::istringstream& out) {
    std::string s;
    while (std::getline(in, s)) {
      ++line;
      const auto hash = s.find('#');
      if (hash != std::string::npos) s.resize(hash);
      if (s.find_first_not_of(" \t\r") == std::string::npos) continue;
      out.clear();
      out.str(s);
      return true;
    }
    return false;
  }
};

// Whole-token numbers: "1.5" is not an index and "0x" is not a coordinate (stream extraction
// would read the leading part and leave the rest for the next field).
bool parse_double(const std::string& tok, double& out) {
  if (tok.empty()) return false;
  char* end = nullptr;
  errno = 0;
  out = std::strtod(tok.c_str(), &end);
  return end == tok.c_str() + tok.size();
}

// A vertex index: an integer token in [0, 2^31 − 1] (the triangles are int32). Reports why not.
std::string parse_index(const std::string& tok, int& out) {
  double v = 0;
  if (!parse_double(tok, v)) return "'" + tok + "' is not a number";
  if (!(v == std::floor(v))) return "vertex index '" + tok + "' is not an integer";
  if (!(v >= 0 && v <= static_cast<double>(std::numeric_limits<int>::max())))
    return "vertex index " + tok + " is outside [0, " + std::to_string(std::numeric_limits<int>::max()) + "]";
  out = static_cast<int>(v);
  return {};
}

std::vector<std::string> tokens(std::istringstream& ls) {
  std::vector<std::string> t;
  for (std::string w; ls >> w;) t.push_back(w);
  return t;
}

std::uintmax_t file_size_or_zero(const std::string& path) {
  std::error_code ec;
  const std::uintmax_t n = std::filesystem::file_size(path, ec);
  return ec ? 0 : n;
}

// Declared counts that the file cannot hold mean a damaged header, not a mesh to allocate
// (99999999999 vertices would be a bare std::bad_alloc otherwise). Small meshes (under 16 MB of
// arrays) are allocated anyway: reading then names the line where the file ends.
void check_counts_fit(const std::string& path, long long nv, long long nf, double min_vertex_bytes, double min_face_bytes,
                      std::uintmax_t available) {
  const double need = static_cast<double>(nv) * min_vertex_bytes + static_cast<double>(nf) * min_face_bytes;
  const double arrays = 24.0 * static_cast<double>(nv) + 12.0 * static_cast<double>(nf);
  if (need > static_cast<double>(available) && arrays > 16.0 * (1 << 20))
    fail(path, fmt::format("the header declares {} vertices and {} faces, more than a file of {} bytes can hold "
                           "(damaged or truncated file?)", nv, nf, available));
}

}  // namespace

SurfaceMesh read_off(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(path, std::string("cannot open mesh file: ") + std::strerror(errno));
  LineReader r{in};
  std::istringstream ls;
  if (!r.next(ls)) fail(path, "empty file");
  std::string first;
  ls >> first;
  // Geomview's header variants [ST][C][N][4][n]OFF: ST (texture coordinates), C (colour) and N
  // (normal) add values after x y z on each vertex line, which are ignored; 4 and n change the
  // dimension. Faces may carry a colour after their indices (ignored too).
  static const std::regex header("^(ST)?(C)?(N)?(4)?(n)?OFF$");
  std::smatch h;
  if (std::regex_match(first, h, header)) {
    if (h[4].matched || h[5].matched)
      fail(path, "line " + std::to_string(r.line) + ": '" + first + "' (4-D or n-D OFF) is not supported; a capsule wall is a surface in 3-D");
    std::string rest;
    std::getline(ls, rest);  // counts may follow the header on the same line
    std::istringstream probe(rest);
    std::string word;
    if (probe >> word && word == "BINARY")
      fail(path, "line " + std::to_string(r.line) + ": binary OFF is not supported (convert it to ASCII OFF or PLY)");
    if (rest.find_first_not_of(" \t\r") == std::string::npos) {
      if (!r.next(ls)) fail(path, "missing counts line after " + first + " header");
    } else {
      ls.clear();
      ls.str(rest);
    }
  } else {
    ls.clear();
    ls.seekg(0);
  }
  const std::vector<std::string> counts = tokens(ls);
  double nv_d = -1, nf_d = -1;
  const double int_max = static_cast<double>(std::numeric_limits<int>::max());
  if (counts.size() < 2 || !parse_double(counts[0], nv_d) || !parse_double(counts[1], nf_d) || nv_d != std::floor(nv_d) ||
      nf_d != std::floor(nf_d) || !(nv_d >= 0 && nv_d <= int_max) || !(nf_d >= 0 && nf_d <= int_max))
    fail(path, "line " + std::to_string(r.line) + ": expected 'nvertices nfaces nedges' (integers in [0, 2147483647])");
  const long nv = static_cast<long>(nv_d), nf = static_cast<long>(nf_d);
  check_counts_fit(path, nv, nf, 6, 8, file_size_or_zero(path));  // shortest lines: "0 0 0\n", "3 0 1 2\n"
  SurfaceMesh m;
  m.vertices.resize(nv, 3);
  m.triangles.resize(nf, 3);
  for (long i = 0; i < nv; ++i) {
    if (!r.next(ls)) fail(path, "unexpected end of file in vertex " + std::to_string(i));
    const std::vector<std::string> t = tokens(ls);
    const std::string where = "line " + std::to_string(r.line) + ": vertex " + std::to_string(i);
    if (t.size() < 3) fail(path, where + " needs three numbers x y z");
    for (int k = 0; k < 3; ++k) {
      if (!parse_double(t[k], m.vertices(i, k))) fail(path, where + ": '" + t[k] + "' is not a number");
      if (!std::isfinite(m.vertices(i, k))) fail(path, where + " has a non-finite coordinate (" + t[k] + ")");
    }
  }
  for (long f = 0; f < nf; ++f) {
    if (!r.next(ls)) fail(path, "unexpected end of file in face " + std::to_string(f));
    const std::vector<std::string> t = tokens(ls);
    const std::string where = "line " + std::to_string(r.line) + ": face " + std::to_string(f);
    double k = 0;
    if (t.empty() || !parse_double(t[0], k) || k != std::floor(k)) fail(path, where + " has no vertex count");
    if (k != 3) fail(path, where + " has " + t[0] + " vertices; only triangles are supported");
    if (t.size() < 4) fail(path, where + " needs three vertex indices");
    for (int j = 0; j < 3; ++j) {
      const std::string why = parse_index(t[1 + j], m.triangles(f, j));
      if (!why.empty()) fail(path, where + ": " + why);
    }
  }
  return finish(std::move(m), path);
}

namespace {

struct PlyProperty {
  std::string name, type, count_type;  // count_type non-empty for list properties
};
struct PlyElement {
  std::string name;
  long count = 0;
  std::vector<PlyProperty> props;
};

int ply_type_size(const std::string& t, const std::string& path) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  fail(path, "unknown PLY property type '" + t + "'");
}

double read_binary_scalar(std::istream& in, const std::string& t, const std::string& path) {
  unsigned char buf[8];
  const int n = ply_type_size(t, path);
  if (!in.read(reinterpret_cast<char*>(buf), n)) fail(path, "unexpected end of binary PLY data");
  auto get = [&](auto v) { std::memcpy(&v, buf, sizeof v); return static_cast<double>(v); };
  if (t == "char" || t == "int8") return get(int8_t{});
  if (t == "uchar" || t == "uint8") return get(uint8_t{});
  if (t == "short" || t == "int16") return get(int16_t{});
  if (t == "ushort" || t == "uint16") return get(uint16_t{});
  if (t == "int" || t == "int32") return get(int32_t{});
  if (t == "uint" || t == "uint32") return get(uint32_t{});
  if (t == "float" || t == "float32") return get(float{});
  return get(double{});
}

}  // namespace

SurfaceMesh read_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot open mesh file: ") + std::strerror(errno));
  std::string line;
  int lineno = 0;
  auto getline = [&]() {
    if (!std::getline(in, line)) fail(path, "unexpected end of PLY header");
    ++lineno;
    if (!line.empty() && line.back() == '\r') line.pop_back();
  };
  getline();
  if (line != "ply") fail(path, "line 1: not a PLY file (missing 'ply' magic)");
  bool binary = false;
  std::vector<PlyElement> elements;
  for (;;) {
    getline();
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "end_header") break;
    if (word == "comment" || word == "obj_info" || word.empty()) continue;
    if (word == "format") {
      std::string fmt;
      ls >> fmt;
      if (fmt == "binary_little_endian") binary = true;
      else if (fmt != "ascii") fail(path, "line " + std::to_string(lineno) + ": PLY format '" + fmt + "' not supported (ascii or binary_little_endian)");
    } else if (word == "element") {
      PlyElement e;
      if (!(ls >> e.name >> e.count) || e.count < 0) fail(path, "line " + std::to_string(lineno) + ": malformed element line");
      elements.push_back(e);
    } else if (word == "property") {
      if (elements.empty()) fail(path, "line " + std::to_string(lineno) + ": property before any element");
      PlyProperty p;
      ls >> p.type;
      if (p.type == "list") ls >> p.count_type >> p.type;
      ls >> p.name;
      elements.back().props.push_back(p);
    } else {
      fail(path, "line " + std::to_string(lineno) + ": unexpected PLY header keyword '" + word + "'");
    }
  }
  {
    // Every element needs some bytes: a number and a separator per ASCII value, the type's size
    // per binary scalar, the count's size per binary list.
    double need = 0;
    for (const PlyElement& e : elements) {
      double per = 0;
      for (const PlyProperty& p : e.props)
        per += binary ? ply_type_size(p.count_type.empty() ? p.type : p.count_type, path) : 2;
      need += static_cast<double>(e.count) * per;
    }
    const std::uintmax_t total = file_size_or_zero(path);
    const std::streamoff at = in.tellg();
    const std::uintmax_t available = at > 0 && static_cast<std::uintmax_t>(at) <= total ? total - static_cast<std::uintmax_t>(at) : 0;
    double arrays = 0;
    for (const PlyElement& e : elements) arrays += 24.0 * static_cast<double>(e.count);
    if (need > static_cast<double>(available) && arrays > 16.0 * (1 << 20)) {  // as check_counts_fit
      std::string declared;
      for (const PlyElement& e : elements) declared += (declared.empty() ? "" : ", ") + std::to_string(e.count) + " " + e.name;
      fail(path, "the header declares " + declared + ", more than the " + std::to_string(available) +
                     " bytes after it can hold (damaged or truncated file?)");
    }
    for (const PlyElement& e : elements)
      if ((e.name == "vertex" || e.name == "face") && e.count > std::numeric_limits<int>::max())
        fail(path, "element " + e.name + " count " + std::to_string(e.count) + " exceeds 2147483647");
  }
  SurfaceMesh m;
  bool have_vertices = false, have_faces = false;
  for (const PlyElement& e : elements) {
    const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    int ix = -1, iy = -1, iz = -1, ilist = -1;
    for (size_t k = 0; k < e.props.size(); ++k) {
      const auto& n = e.props[k].name;
      if (n == "x") ix = static_cast<int>(k);
      if (n == "y") iy = static_cast<int>(k);
      if (n == "z") iz = static_cast<int>(k);
      if ((n == "vertex_indices" || n == "vertex_index") && !e.props[k].count_type.empty()) ilist = static_cast<int>(k);
    }
    if (is_vertex && (ix < 0 || iy < 0 || iz < 0)) fail(path, "PLY vertex element lacks x, y or z");
    if (is_face && ilist < 0) fail(path, "PLY face element lacks a vertex_indices list");
    if (is_vertex) m.vertices.resize(e.count, 3), have_vertices = true;
    if (is_face) m.triangles.resize(e.count, 3), have_faces = true;
    for (long i = 0; i < e.count; ++i) {
      std::istringstream ls;
      if (!binary) {
        getline();
        ls.str(line);
      }
      for (size_t k = 0; k < e.props.size(); ++k) {
        const PlyProperty& p = e.props[k];
        std::string tok;
        auto scalar = [&](const std::string& type) {
          if (binary) {
            const double v = read_binary_scalar(in, type, path);
            tok = fmt::format("{}", v);
            return v;
          }
          double v;
          if (!(ls >> tok)) fail(path, "line " + std::to_string(lineno) + ": too few values for " + e.name + " " + std::to_string(i));
          if (!parse_double(tok, v)) fail(path, "line " + std::to_string(lineno) + ": " + e.name + " " + std::to_string(i) + ": '" + tok + "' is not a number");
          return v;
        };
        const std::string where = (binary ? std::string() : "line " + std::to_string(lineno) + ": ") + e.name + " " + std::to_string(i);
        if (p.count_type.empty()) {
          const double v = scalar(p.type);
          if (is_vertex && static_cast<int>(k) == ix) m.vertices(i, 0) = v;
          if (is_vertex && static_cast<int>(k) == iy) m.vertices(i, 1) = v;
          if (is_vertex && static_cast<int>(k) == iz) m.vertices(i, 2) = v;
        } else {
          const double count = scalar(p.count_type);
          if (!(count >= 0 && count <= 1 << 20 && count == std::floor(count)))
            fail(path, where + ": list length '" + tok + "' is not an integer in [0, 2^20]");
          const int n = static_cast<int>(count);
          if (is_face && static_cast<int>(k) == ilist && n != 3)
            fail(path, where + " has " + std::to_string(n) + " vertices; only triangles are supported");
          for (int j = 0; j < n; ++j) {
            scalar(p.type);
            if (is_face && static_cast<int>(k) == ilist) {
              const std::string why = parse_index(tok, m.triangles(i, j));
              if (!why.empty()) fail(path, where + ": " + why);
            }
          }
        }
      }
    }
  }
  if (!have_vertices || !have_faces) fail(path, "PLY file needs both a vertex and a face element");
  return finish(std::move(m), path);
}

SurfaceMesh read_mesh(const std::string& path) {
  if (const std::string problem = io::input_file_problem(path, io::kMaxMeshBytes); !problem.empty())
    fail(path, "cannot open mesh file: it " + problem);
  const std::string ext = lower_ext(path);
  try {
    if (ext == "off") return read_off(path);
    if (ext == "ply") return read_ply(path);
  } catch (const std::bad_alloc&) {
    fail(path, "not enough memory to read this mesh");
  }
  fail(path, "unknown mesh file extension '." + ext + "' (expected .off or .ply)");
}

void write_mesh(const SurfaceMesh& mesh, const std::string& path) {
  const std::string ext = lower_ext(path);
  if (ext != "off" && ext != "ply") fail(path, "unknown mesh file extension '." + ext + "' (expected .off or .ply)");
  std::ofstream out(path);
  if (!out) fail(path, std::string("cannot write mesh file: ") + std::strerror(errno));
  out << std::setprecision(17);
  if (ext == "off") {
    out << "OFF\n" << mesh.num_nodes() << ' ' << mesh.num_elements() << " 0\n";
  } else {
    out << "ply\nformat ascii 1.0\nelement vertex " << mesh.num_nodes()
        << "\nproperty double x\nproperty double y\nproperty double z\nelement face " << mesh.num_elements()
        << "\nproperty list uchar int vertex_indices\nend_header\n";
  }
  for (Eigen::Index i = 0; i < mesh.num_nodes(); ++i)
    out << mesh.vertices(i, 0) << ' ' << mesh.vertices(i, 1) << ' ' << mesh.vertices(i, 2) << '\n';
  for (Eigen::Index e = 0; e < mesh.num_elements(); ++e)
    out << "3 " << mesh.triangles(e, 0) << ' ' << mesh.triangles(e, 1) << ' ' << mesh.triangles(e, 2) << '\n';
  out.close();  // a full disk shows at the final flush
  if (!out) fail(path, "write failed");
}

}  // namespace capsflow
