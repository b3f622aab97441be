// Run identity: run ids, the mesh hash, and reading a folder's identity from run.h5 (also from
// folders written before run ids).
#include <gtest/gtest.h>

#include <set>

#include "capsflow/core/io/h5.hpp"
#include "capsflow/core/io/results_writer.hpp"
#include "capsflow/core/io/run_identity.hpp"
#include "temp_dir.hpp"

namespace capsflow::io {
namespace {
using testing::TempDir;
using testing::tetrahedron;

TEST(RunIdentity, RunIdsAreLongHexAndDistinct) {
  std::set<std::string> ids;
  for (int i = 0; i < 100; ++i) {
    const std::string id = new_run_id();
    EXPECT_EQ(id.size(), 32u);
    EXPECT_EQ(id.find_first_not_of("0123456789abcdef"), std::string::npos) << id;
    ids.insert(id);
  }
  EXPECT_EQ(ids.size(), 100u);  // 128 random bits: a collision would be a broken generator
}

TEST(RunIdentity, MeshHashSeesEveryBit) {
  const SurfaceMesh m = tetrahedron();
  const std::string h = mesh_hash(m.vertices, m.triangles);
  EXPECT_EQ(h, mesh_hash(m.vertices, m.triangles));
  Points x = m.vertices;
  x(2, 1) = std::nextafter(x(2, 1), 0.0);  // one ulp
  EXPECT_NE(mesh_hash(x, m.triangles), h);
  Triangles t = m.triangles;
  std::swap(t(0, 1), t(0, 2));
  EXPECT_NE(mesh_hash(m.vertices, t), h);
}

TEST(RunIdentity, ReadFromRunFileOldFilesAndRestarts) {
  TempDir dir;
  const SurfaceMesh m = tetrahedron();
  EXPECT_FALSE(read_folder_identity(dir.path()).has_run);  // no run.h5: nothing to protect
  { ResultsWriter w(dir.path(), m, {{"run_id", "aaaa"}, {"mesh_hash", mesh_hash(m.vertices, m.triangles)}}); }
  FolderIdentity id = read_folder_identity(dir.path());
  EXPECT_TRUE(id.has_run);
  EXPECT_EQ(id.run_id, "aaaa");
  EXPECT_EQ(id.mesh_hash, mesh_hash(m.vertices, m.triangles));  // recomputed from /mesh, bit for bit

  // Written before run ids: no /metadata/run_id ...
  {
    h5::File f = h5::File::open(dir / kRunH5, h5::File::Mode::read_write);
    f.remove("metadata/run_id");
    f.close();
  }
  EXPECT_EQ(read_folder_identity(dir.path()).run_id, "");
  // ... until a restart recorded one; the newest restart counts (10 sorts after 9).
  ResultsWriter::reopen(dir.path(), 0.0, {{"run_id", "bbbb"}});
  for (int i = 0; i < 10; ++i) ResultsWriter::reopen(dir.path(), 0.0, {{"command_line", "x"}});
  ResultsWriter::reopen(dir.path(), 0.0, {{"run_id", "cccc"}});
  EXPECT_EQ(read_folder_identity(dir.path()).run_id, "cccc");

  testing::write_text(dir / kRunH5, "damaged");
  try {
    read_folder_identity(dir.path());
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot read the identity of the run in"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace capsflow::io
