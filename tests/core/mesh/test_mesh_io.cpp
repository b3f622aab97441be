// OFF/PLY round trips and malformed-file errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/mesh/mesh_io.hpp"

using namespace capsflow;
namespace fs = std::filesystem;

namespace {
struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / ("capsflow-meshio-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string file(const std::string& name, const std::string& content = "") const {
    const auto p = (path / name).string();
    if (!content.empty()) std::ofstream(p) << content;
    return p;
  }
};
std::string read_error(const std::string& path) {
  try {
    read_mesh(path);
  } catch (const MeshError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(MeshIO, RoundTripOffAndPlyExactly) {
  TempDir dir;
  const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 2);
  for (const char* name : {"a.off", "a.ply"}) {
    const auto p = dir.file(name);
    write_mesh(m, p);
    const SurfaceMesh r = read_mesh(p);
    EXPECT_EQ(r.triangles, m.triangles);
    EXPECT_EQ(r.vertices, m.vertices);  // 17 significant digits: exact round trip of doubles
  }
}

TEST(MeshIO, BinaryPly) {
  TempDir dir;
  const SurfaceMesh m = make_sphere_mesh(BaseSolid::Octahedron, 1);
  const auto p = dir.file("b.ply");
  {
    std::ofstream out(p, std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\ncomment test\nelement vertex " << m.num_nodes()
        << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face "
        << m.num_elements() << "\nproperty list uchar int vertex_indices\nend_header\n";
    for (Eigen::Index i = 0; i < m.num_nodes(); ++i) {
      for (int k = 0; k < 3; ++k) {
        const float v = static_cast<float>(m.vertices(i, k));
        out.write(reinterpret_cast<const char*>(&v), 4);
      }
      const unsigned char red = 7;
      out.write(reinterpret_cast<const char*>(&red), 1);
    }
    for (Eigen::Index e = 0; e < m.num_elements(); ++e) {
      const unsigned char three = 3;
      out.write(reinterpret_cast<const char*>(&three), 1);
      for (int k = 0; k < 3; ++k) {
        const int32_t v = m.triangles(e, k);
        out.write(reinterpret_cast<const char*>(&v), 4);
      }
    }
  }
  const SurfaceMesh r = read_mesh(p);
  EXPECT_EQ(r.triangles, m.triangles);
  EXPECT_LT((r.vertices - m.vertices).cwiseAbs().maxCoeff(), 1e-7);  // float storage: 2^-24 relative
}

TEST(MeshIO, MalformedFiles) {
  TempDir dir;
  EXPECT_NE(read_error(dir.file("missing.off")).find("cannot open"), std::string::npos);
  EXPECT_NE(read_error(dir.file("x.stl", "solid")).find("unknown mesh file extension"), std::string::npos);
  EXPECT_NE(read_error(dir.file("short.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n")).find("unexpected end of file"), std::string::npos);
  EXPECT_NE(read_error(dir.file("quad.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")).find("only triangles"),
            std::string::npos);
  EXPECT_NE(read_error(dir.file("bad.off", "OFF\n3 1 0\n0 0 zero\n")).find("line 3"), std::string::npos);
  EXPECT_NE(read_error(dir.file("bad.ply", "plx\n")).find("not a PLY"), std::string::npos);
  // An open surface read from file: the topology error carries the file name.
  const std::string open = read_error(dir.file("open.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n"));
  EXPECT_NE(open.find("open.off"), std::string::npos) << open;
  EXPECT_NE(open.find("elements"), std::string::npos) << open;  // fewer than 4 elements
}
