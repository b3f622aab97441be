#include "capsflow/core/mesh/mesh_io.hpp"

#include <cstring>
#include <fstream>
#include <iomanip>
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

}  // namespace

SurfaceMesh read_off(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(path, std::string("cannot open mesh file: ") + std::strerror(errno));
  LineReader r{in};
  std::istringstream ls;
  if (!r.next(ls)) fail(path, "empty file");
  std::string first;
  ls >> first;
  if (first == "OFF") {
    std::string rest;
    std::getline(ls, rest);  // counts may follow the header on the same line
    if (rest.find_first_not_of(" \t\r") == std::string::npos) {
      if (!r.next(ls)) fail(path, "missing counts line after OFF header");
    } else {
      ls.clear();
      ls.str(rest);
    }
  } else {
    ls.clear();
    ls.seekg(0);
  }
  long nv = -1, nf = -1, ne = 0;
  if (!(ls >> nv >> nf) || nv < 0 || nf < 0) fail(path, "line " + std::to_string(r.line) + ": expected 'nvertices nfaces nedges'");
  (void)(ls >> ne);
  SurfaceMesh m;
  m.vertices.resize(nv, 3);
  m.triangles.resize(nf, 3);
  for (long i = 0; i < nv; ++i) {
    if (!r.next(ls)) fail(path, "unexpected end of file in vertex " + std::to_string(i));
    if (!(ls >> m.vertices(i, 0) >> m.vertices(i, 1) >> m.vertices(i, 2)))
      fail(path, "line " + std::to_string(r.line) + ": vertex " + std::to_string(i) + " needs three numbers");
  }
  for (long f = 0; f < nf; ++f) {
    if (!r.next(ls)) fail(path, "unexpected end of file in face " + std::to_string(f));
    int k = 0;
    if (!(ls >> k)) fail(path, "line " + std::to_string(r.line) + ": face " + std::to_string(f) + " has no vertex count");
    if (k != 3) fail(path, "line " + std::to_string(r.line) + ": face " + std::to_string(f) + " has " + std::to_string(k) + " vertices; only triangles are supported");
    if (!(ls >> m.triangles(f, 0) >> m.triangles(f, 1) >> m.triangles(f, 2)))
      fail(path, "line " + std::to_string(r.line) + ": face " + std::to_string(f) + " needs three vertex indices");
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
        auto scalar = [&](const std::string& type) {
          if (binary) return read_binary_scalar(in, type, path);
          double v;
          if (!(ls >> v)) fail(path, "line " + std::to_string(lineno) + ": too few values for " + e.name + " " + std::to_string(i));
          return v;
        };
        if (p.count_type.empty()) {
          const double v = scalar(p.type);
          if (is_vertex && static_cast<int>(k) == ix) m.vertices(i, 0) = v;
          if (is_vertex && static_cast<int>(k) == iy) m.vertices(i, 1) = v;
          if (is_vertex && static_cast<int>(k) == iz) m.vertices(i, 2) = v;
        } else {
          const int n = static_cast<int>(scalar(p.count_type));
          if (is_face && static_cast<int>(k) == ilist && n != 3)
            fail(path, "face " + std::to_string(i) + " has " + std::to_string(n) + " vertices; only triangles are supported");
          for (int j = 0; j < n; ++j) {
            const double v = scalar(p.type);
            if (is_face && static_cast<int>(k) == ilist) m.triangles(i, j) = static_cast<int>(v);
          }
        }
      }
    }
  }
  if (!have_vertices || !have_faces) fail(path, "PLY file needs both a vertex and a face element");
  return finish(std::move(m), path);
}

SurfaceMesh read_mesh(const std::string& path) {
  const std::string ext = lower_ext(path);
  if (ext == "off") return read_off(path);
  if (ext == "ply") return read_ply(path);
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
  if (!out) fail(path, "write failed");
}

}  // namespace capsflow
