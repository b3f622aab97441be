// OFF/PLY round trips and malformed-file errors.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include <sys/stat.h>

#include "capsflow/core/io/input_file.hpp"
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

namespace {
// The octahedron as OFF text with a custom header and extra values after x y z.
std::string octa_off(const std::string& header, const std::string& vertex_extra) {
  const SurfaceMesh m = make_sphere_mesh(BaseSolid::Octahedron, 0);
  std::ostringstream s;
  s << header << "\n" << m.num_nodes() << " " << m.num_elements() << " 0\n";
  for (Eigen::Index i = 0; i < m.num_nodes(); ++i)
    s << m.vertices(i, 0) << " " << m.vertices(i, 1) << " " << m.vertices(i, 2) << vertex_extra << "\n";
  for (Eigen::Index e = 0; e < m.num_elements(); ++e)
    s << "3 " << m.triangles(e, 0) << " " << m.triangles(e, 1) << " " << m.triangles(e, 2) << "\n";
  return s.str();
}
std::string ply_header(long vertices, long faces) {
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(faces) +
         "\nproperty list uchar int vertex_indices\nend_header\n";
}
const char* kOctaVertices = "0 0 1\n1 0 0\n0 1 0\n-1 0 0\n0 -1 0\n0 0 -1\n";
}  // namespace

TEST(MeshIO, OffHeaderVariantsCoffNoffAreRead) {
  TempDir dir;
  const SurfaceMesh m = make_sphere_mesh(BaseSolid::Octahedron, 0);
  for (const auto& [header, extra] : std::vector<std::pair<std::string, std::string>>{
           {"COFF", " 255 0 0 255"}, {"NOFF", " 0 0 1"}, {"CNOFF", " 0 0 1 0.5 0.5 0.5 1"}, {"STOFF", " 0.5 0.5"}}) {
    const auto p = dir.file("v.off", octa_off(header, extra));
    EXPECT_EQ(read_error(p), "") << header;
    EXPECT_EQ(read_mesh(p).triangles, m.triangles) << header;
  }
  const std::string e4 = read_error(dir.file("four.off", octa_off("4OFF", " 0")));
  EXPECT_NE(e4.find("4-D or n-D OFF"), std::string::npos) << e4;
  const std::string eb = read_error(dir.file("bin.off", "OFF BINARY\n"));
  EXPECT_NE(eb.find("binary OFF is not supported"), std::string::npos) << eb;
}

TEST(MeshIO, NanAndNonNumbersInOffAreNamed) {
  TempDir dir;
  // Once "vertex 0 needs three numbers": the stream refused "nan" without saying why.
  const std::string e = read_error(dir.file("nan.off", "OFF\n6 8 0\nnan 0 1\n1 0 0\n"));
  EXPECT_NE(e.find("line 3: vertex 0 has a non-finite coordinate (nan)"), std::string::npos) << e;
  const std::string f = read_error(dir.file("half.off", "OFF\n6 8 0\n0 0 1.5x\n"));
  EXPECT_NE(f.find("line 3: vertex 0: '1.5x' is not a number"), std::string::npos) << f;
}

TEST(MeshIO, VertexIndicesMustBeIntegersInRange) {
  TempDir dir;
  const std::string tail = "3 0 2 1\n3 0 3 2\n3 0 4 3\n3 0 1 4\n3 5 1 2\n3 5 2 3\n3 5 3 4\n";
  // 99999999999 does not fit int32: once reported as -2147483648 (a cast), now named as it is.
  const std::string big = read_error(dir.file("big.ply", ply_header(6, 8) + kOctaVertices + tail + "3 5 4 99999999999\n"));
  EXPECT_NE(big.find("vertex index 99999999999 is outside [0, 2147483647]"), std::string::npos) << big;
  // A non-integer index was truncated to 1 (and the mesh accepted).
  const std::string frac = read_error(dir.file("frac.ply", ply_header(6, 8) + kOctaVertices + tail + "3 5 4 1.5\n"));
  EXPECT_NE(frac.find("vertex index '1.5' is not an integer"), std::string::npos) << frac;
  const std::string off = read_error(dir.file("frac.off", "OFF\n6 8 0\n" + std::string(kOctaVertices) + tail + "3 5 4 1.5\n"));
  EXPECT_NE(off.find("line 16: face 7: vertex index '1.5' is not an integer"), std::string::npos) << off;
  EXPECT_EQ(read_error(dir.file("ok.ply", ply_header(6, 8) + kOctaVertices + tail + "3 5 4 1\n")), "");
}

TEST(MeshIO, HugeCountsAreAClearErrorNotBadAlloc) {
  TempDir dir;
  // 99999999999 vertices would be 2.4 TB of coordinates: a damaged header, not a mesh.
  const std::string ply = read_error(dir.file("huge.ply", ply_header(99999999999L, 8) + kOctaVertices));
  EXPECT_NE(ply.find("declares 99999999999 vertex, 8 face"), std::string::npos) << ply;
  const std::string off = read_error(dir.file("huge.off", "OFF\n2000000000 8 0\n" + std::string(kOctaVertices)));
  EXPECT_NE(off.find("declares 2000000000 vertices and 8 faces, more than a file of"), std::string::npos) << off;
  const std::string over = read_error(dir.file("over.off", "OFF\n99999999999 8 0\n"));
  EXPECT_NE(over.find("integers in [0, 2147483647]"), std::string::npos) << over;
}

// Only regular files are read: a folder, a FIFO or a device would block or read for ever
// (/dev/zero named through a .off link grew memory by 5 GB in 7 s).
TEST(MeshIO, OnlyRegularFilesOfBoundedSizeAreRead) {
  TempDir d;
  const fs::path folder = d.path / "looks_like.off";
  fs::create_directories(folder);
  EXPECT_NE(read_error(folder.string()).find("is a folder, not a file"), std::string::npos) << read_error(folder.string());
  const std::string fifo = (d.path / "pipe.off").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(read_error(fifo).find("is a FIFO, not a regular file"), std::string::npos) << read_error(fifo);
  const fs::path zero = d.path / "zero.off";
  fs::create_symlink("/dev/zero", zero);
  EXPECT_NE(read_error(zero.string()).find("is a character device"), std::string::npos) << read_error(zero.string());
  // A sparse file just over the cap: refused by its size, before a byte is read. Under a
  // file-size limit below the cap (`ulimit -f`) the file cannot be made: that case is skipped.
  const std::string big = d.file("big.off");
  { std::ofstream(big) << "OFF\n"; }
  const auto previous = std::signal(SIGXFSZ, SIG_IGN);
  std::error_code ec;
  fs::resize_file(big, io::kMaxMeshBytes + 1, ec);
  std::signal(SIGXFSZ, previous);
  if (ec == std::errc::file_too_large) GTEST_SKIP() << "a file-size limit forbids the " << io::kMaxMeshBytes + 1 << "-byte sparse file";
  ASSERT_FALSE(ec) << ec.message();
  EXPECT_NE(read_error(big).find("larger than the 1024 MB"), std::string::npos) << read_error(big);
}
