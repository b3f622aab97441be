// ResultsWriter: run.h5 layout, XDMF well-formed and consistent with run.h5, CSV, summary,
// timings, restart truncation, a restart over a run.h5 damaged by a kill, several capsules in one
// union mesh (/mesh/parts, one XDMF grid per capsule), and writing while another process holds
// run.h5 open.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ostream>
#include <regex>

#include "capsflow/core/io/h5.hpp"
#include "capsflow/core/io/io_error.hpp"
#include "capsflow/core/io/results_writer.hpp"
#include "capsflow/core/io/timeseries_csv.hpp"
#include "temp_dir.hpp"

namespace capsflow::io {
namespace {
using testing::listing;
using testing::read_text;
using testing::TempDir;
using testing::tetrahedron;
using testing::write_text;

nlohmann::json metadata() {
  return {{"scene_toml", "[mesh]\nlevel = 4\n"},
          {"scene_resolved", {{"mesh", {{"level", 4}}}}},
          {"command_line", "capsflow run scene.toml -o out"},
          {"threads", 2},
          {"git/hash", "abc123"}};
}

// Step k: positions scaled by (1 + t), a vector and a scalar field.
void write_test_step(ResultsWriter& w, const SurfaceMesh& mesh, double t) {
  const Points x = mesh.vertices * (1 + t);
  const Eigen::VectorXd tension = Eigen::VectorXd::Constant(mesh.num_nodes(), t);
  w.write_step(t, x, {{"velocity", x * 0.5}, {"tension", tension}});
}

// Minimal XML well-formedness: every opening tag closed in order; returns false otherwise.
bool tags_balanced(const std::string& xml) {
  std::vector<std::string> stack;
  for (std::size_t i = xml.find('<'); i != std::string::npos; i = xml.find('<', i + 1)) {
    const std::size_t end = xml.find('>', i);
    if (end == std::string::npos) return false;
    const std::string tag = xml.substr(i + 1, end - i - 1);
    if (tag.empty() || tag[0] == '?' || tag[0] == '!') continue;  // declaration, comment
    if (tag[0] == '/') {
      if (stack.empty() || stack.back() != tag.substr(1)) return false;
      stack.pop_back();
    } else if (tag.back() != '/') {
      stack.push_back(tag.substr(0, tag.find_first_of(" \n")));
    }
  }
  return stack.empty();
}

std::vector<std::string> all_matches(const std::string& text, const std::regex& re) {
  std::vector<std::string> out;
  for (std::sregex_iterator it(text.begin(), text.end(), re), end; it != end; ++it) {
    out.push_back((*it)[1].str());
  }
  return out;
}

// Every DataItem that `item` matches ((1) its Dimensions, (2) its dataset in run.h5) names a dataset
// of that file with that shape; returns how many there are.
std::size_t check_data_items(const std::string& xml, const std::regex& item, const std::filesystem::path& run_h5) {
  const h5::File f = h5::File::open(run_h5);
  std::size_t items = 0;
  for (std::sregex_iterator it(xml.begin(), xml.end(), item), end; it != end; ++it, ++items) {
    const std::string dims = (*it)[1].str(), dataset = (*it)[2].str();
    EXPECT_TRUE(f.exists(dataset)) << dataset;
    if (!f.exists(dataset)) continue;
    std::string shape;
    for (hsize_t d : f.shape(dataset)) shape += (shape.empty() ? "" : " ") + std::to_string(d);
    EXPECT_EQ(shape, dims) << dataset;
  }
  return items;
}

std::size_t count_uniform_grids(const std::string& xml) {
  return all_matches(xml, std::regex("<Grid Name=\"([^\"]*)\" GridType=\"Uniform\">")).size();
}

TEST(ResultsWriter, RunFileHoldsMeshAndMetadata) {
  TempDir dir;
  const SurfaceMesh mesh = tetrahedron();
  ResultsWriter w(dir.path(), mesh, metadata());
  h5::File f = h5::File::open(dir / "run.h5");
  EXPECT_EQ(f.read_matrix<int>("mesh/triangles"), h5::RowMatrixXi(mesh.triangles));  // exact
  EXPECT_EQ(f.read_matrix<double>("mesh/reference_positions"), h5::RowMatrixXd(mesh.vertices));
  h5::Group meta = f.open_group("metadata");
  EXPECT_EQ(meta.read_string("scene_toml"), "[mesh]\nlevel = 4\n");  // verbatim
  EXPECT_EQ(nlohmann::json::parse(meta.read_string("scene_resolved")),
            metadata()["scene_resolved"]);
  EXPECT_EQ(meta.read_string("command_line"), "capsflow run scene.toml -o out");
  EXPECT_EQ(meta.read_string("git_hash"), "abc123");  // '/' is not allowed in HDF5 names
  EXPECT_EQ(meta.attribute_int("threads"), 2);
  EXPECT_EQ(meta.attribute_int("schema_version"), kOutputSchemaVersion);
  EXPECT_EQ(meta.attribute_string("hdf5_version"), h5::library_version());
  EXPECT_EQ(meta.attribute_string("created_utc").size(), 20u);  // 2026-11-22T02:50:00Z
  EXPECT_TRUE(meta.has_attribute("hostname"));
  EXPECT_TRUE(f.children() == (std::vector<std::string>{"mesh", "metadata", "steps"}));
  // No run.xmf before the first step: ParaView 5.11's XDMF Reader crashes on an empty collection.
  EXPECT_FALSE(std::filesystem::exists(dir / "run.xmf"));
}

TEST(ResultsWriter, XdmfAfterThreeStepsIsWellFormedAndPointsAtExistingDatasets) {
  TempDir dir;
  const SurfaceMesh mesh = tetrahedron();
  ResultsWriter w(dir.path(), mesh, metadata());
  for (double t : {0.0, 0.1, 0.2}) write_test_step(w, mesh, t);
  const std::string xml = read_text(dir / "run.xmf");

  EXPECT_TRUE(tags_balanced(xml)) << xml;
  EXPECT_NE(xml.find("<Xdmf Version=\"3.0\">"), std::string::npos);
  EXPECT_NE(xml.find("GridType=\"Collection\" CollectionType=\"Temporal\""), std::string::npos);
  EXPECT_EQ(count_uniform_grids(xml), 3u);
  EXPECT_EQ(all_matches(xml, std::regex("<Time Value=\"([^\"]*)\"/>")),
            (std::vector<std::string>{"0", "0.1", "0.2"}));  // shortest exact decimal
  EXPECT_EQ(all_matches(xml, std::regex("AttributeType=\"(\\w+)\" Center=\"Node\"")).size(), 6u);

  // Every DataItem names a dataset of run.h5 whose shape matches Dimensions.
  const std::regex item("Dimensions=\"([0-9 ]+)\"[^>]*>run\\.h5:([^<]+)</DataItem>");
  const std::size_t items = check_data_items(xml, item, dir / "run.h5");
  EXPECT_EQ(items, 3u * 4u);  // topology, geometry, 2 fields per step

  // The step data itself.
  h5::File f = h5::File::open(dir / "run.h5");
  h5::Group s1 = f.open_group("steps/000001");
  EXPECT_EQ(s1.attribute_double("time"), 0.1);  // exact: stored as given
  EXPECT_EQ(s1.read_matrix<double>("positions"), h5::RowMatrixXd(mesh.vertices * 1.1));
  EXPECT_EQ(s1.read_vector<double>("tension"), Eigen::VectorXd::Constant(4, 0.1));
  EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"run.h5", "run.xmf"}));  // no temps
}

TEST(ResultsWriter, RejectsBadSteps) {
  TempDir dir;
  const SurfaceMesh mesh = tetrahedron();
  ResultsWriter w(dir.path(), mesh, metadata());
  write_test_step(w, mesh, 0.5);
  const Points x = mesh.vertices;
  EXPECT_THROW(w.write_step(0.5, x), std::invalid_argument);  // time must increase strictly
  EXPECT_THROW(w.write_step(0.6, Points(3, 3)), std::invalid_argument);  // wrong node count
  EXPECT_THROW(w.write_step(0.6, x, {{"f", Eigen::MatrixXd::Zero(4, 2)}}), std::invalid_argument);
  EXPECT_THROW(w.write_step(0.6, x, {{"positions", x}}), std::invalid_argument);
  EXPECT_THROW(w.write_step(0.6, x, {{"a", x}, {"a", x}}), std::invalid_argument);
  EXPECT_THROW(w.write_step(0.6, x, {{"a/b", x}}), std::invalid_argument);  // not an HDF5 name
  EXPECT_THROW(w.write_step(NAN, x), std::invalid_argument);
  EXPECT_EQ(w.num_steps(), 1u);
  EXPECT_EQ(count_uniform_grids(read_text(dir / "run.xmf")), 1u);
}

TEST(ResultsWriter, SummaryAndTimings) {
  TempDir dir;
  ResultsWriter w(dir.path(), tetrahedron(), metadata());
  const nlohmann::json summary = {{"t", 5.0},
                                  {"steps", 50000},
                                  {"steady", true},
                                  {"D12", 0.123456789012345678},
                                  {"L", {1.1, 0.9, 1.0}}};
  w.write_summary(summary);
  EXPECT_EQ(nlohmann::json::parse(read_text(dir / "summary.json")), summary);  // doubles exact
  w.write_timings({{"step", {{"fluid", 1.5}, {"shell", 0.25}}}, {"total", 2.0}});
  w.write_timings({{"step", {{"fluid", 3.0}}}});  // replaces the earlier table
  h5::File f = h5::File::open(dir / "run.h5");
  h5::Group g = f.open_group("timing");
  EXPECT_EQ(g.attribute_double("step.fluid"), 3.0);
  EXPECT_FALSE(g.has_attribute("total"));
  EXPECT_EQ(nlohmann::json::parse(g.read_string("json"))["step"]["fluid"], 3.0);
  w.append_row({{"t", 0.0}, {"D12", 0.0}});
  EXPECT_EQ(read_text(dir / "timeseries.csv"), "t,D12\n0,0\n");
  // A new run in the same folder starts new series, even without prepare_output_folder.
  ResultsWriter again(dir.path(), tetrahedron(), metadata());
  EXPECT_FALSE(std::filesystem::exists(dir / "timeseries.csv"));
  EXPECT_FALSE(std::filesystem::exists(dir / "summary.json"));
}

TEST(ResultsWriter, FieldNamesAreEscapedInXdmf) {
  TempDir dir;
  const SurfaceMesh mesh = tetrahedron();
  ResultsWriter w(dir.path(), mesh, metadata());
  w.write_step(0.0, mesh.vertices, {{"a<b>&\"c\"", Eigen::VectorXd::Zero(4)}});
  const std::string xml = read_text(dir / "run.xmf");
  EXPECT_TRUE(tags_balanced(xml)) << xml;
  EXPECT_NE(xml.find("Name=\"a&lt;b&gt;&amp;&quot;c&quot;\""), std::string::npos) << xml;
}

TEST(ResultsWriter, RestartTruncatesLaterStepsAndRows) {
  TempDir dir;
  const SurfaceMesh mesh = tetrahedron();
  {
    ResultsWriter w(dir.path(), mesh, metadata());
    for (int k = 0; k < 5; ++k) {
      const double t = 0.1 * k;
      write_test_step(w, mesh, t);
      w.append_row({{"t", t}, {"D12", 0.01 * k}});
    }
  }
  ResultsWriter w =
      ResultsWriter::reopen(dir.path(), 0.2, {{"command_line", "capsflow run --restart"}});
  EXPECT_EQ(w.num_steps(), 3u);  // t = 0, 0.1, 0.2 (0.1 * 2 == 0.2 exactly)
  EXPECT_EQ(w.last_time(), 0.1 * 2);
  EXPECT_EQ(w.num_nodes(), 4);
  {
    h5::File f = h5::File::open(dir / "run.h5");
    EXPECT_EQ(f.open_group("steps").children(),
              (std::vector<std::string>{"000000", "000001", "000002"}));
    EXPECT_EQ(f.open_group("metadata/restarts/0").read_string("command_line"),
              "capsflow run --restart");
    EXPECT_EQ(f.open_group("metadata/restarts/0").attribute_double("t_restart"), 0.2);
  }
  std::string xml = read_text(dir / "run.xmf");
  EXPECT_EQ(count_uniform_grids(xml), 3u);
  EXPECT_EQ(all_matches(xml, std::regex("<Time Value=\"([^\"]*)\"/>")).back(), "0.2");
  EXPECT_EQ(read_text(dir / "timeseries.csv"), "t,D12\n0,0\n0.1,0.01\n0.2,0.02\n");

  // The continued run appends cleanly after the restart point.
  write_test_step(w, mesh, 0.30000000000000004);
  w.append_row({{"t", 0.30000000000000004}, {"D12", 0.03}});
  xml = read_text(dir / "run.xmf");
  EXPECT_TRUE(tags_balanced(xml));
  EXPECT_EQ(count_uniform_grids(xml), 4u);
  EXPECT_NE(xml.find("run.h5:/steps/000003/positions"), std::string::npos);
  EXPECT_EQ(read_text(dir / "timeseries.csv"),
            "t,D12\n0,0\n0.1,0.01\n0.2,0.02\n0.30000000000000004,0.03\n");
  h5::File f = h5::File::open(dir / "run.h5");
  EXPECT_EQ(f.open_group("steps").children().size(), 4u);
}

TEST(ResultsWriter, RestartWritesBackTheCsvRowsACrashCut) {
  TempDir dir;
  const SurfaceMesh mesh = tetrahedron();
  const std::filesystem::path csv = dir / "timeseries.csv";
  {
    ResultsWriter w(dir.path(), mesh, metadata());
    for (int k = 0; k < 3; ++k) {
      const double t = 0.1 * k;
      write_test_step(w, mesh, t);
      // 1/3 needs all 17 digits; NaN is written as an empty field: both must come back verbatim.
      w.append_row({{"t", t}, {"D12", k / 3.0}, {"steady", k == 0 ? std::nan("") : 0.5}});
    }
  }
  const std::string full = read_text(csv);
  ASSERT_EQ(full, "t,D12,steady\n0,0,\n0.1,0.3333333333333333,0.5\n0.2,0.6666666666666666,0.5\n");
  // Killed while writing the row at the checkpoint time: the file ends mid-row.
  std::filesystem::resize_file(csv, full.size() - 5);
  ResultsWriter::reopen(dir.path(), 0.1 * 2);
  EXPECT_EQ(read_text(csv), full) << "the cut row is written back from run.h5";
  // Two rows lost: both come back; a restart before them keeps only the earlier ones.
  std::filesystem::resize_file(csv, std::string("t,D12,steady\n0,0,\n").size());
  ResultsWriter::reopen(dir.path(), 0.2);
  EXPECT_EQ(read_text(csv), full);
  ResultsWriter::reopen(dir.path(), 0.15);
  EXPECT_EQ(read_text(csv), "t,D12,steady\n0,0,\n0.1,0.3333333333333333,0.5\n");
}

// Steps at t = 0, 0.1, 0.2, 0.3, each with its CSV row and a profile, as a run writes them.
void write_four_outputs(const std::filesystem::path& folder, const SurfaceMesh& mesh) {
  ResultsWriter w(folder, mesh, metadata());
  for (int k = 0; k < 4; ++k) {
    const double t = 0.1 * k;
    write_test_step(w, mesh, t);
    w.write_profiles({{"x1x3", mesh.vertices * (1 + t), Eigen::VectorXi::LinSpaced(2, 0, 4)}});
    w.append_row({{"t", t}, {"D12", 0.01 * k}});
  }
}

// Makes `object` unreadable the way a SIGKILL during its write was seen to: its object header's
// version byte is not one HDF5 knows ("bad object header version number"); HDF5 can then neither
// read nor unlink it.
void damage_object_header(const std::filesystem::path& file, const std::string& object) {
  haddr_t addr = HADDR_UNDEF;
  {
    const h5::File f = h5::File::open(file);
#if H5_VERSION_GE(1, 12, 0)
    H5O_info1_t info;
    ASSERT_GE(H5Oget_info_by_name1(f.id(), object.c_str(), &info, H5P_DEFAULT), 0) << object;
#else
    H5O_info_t info;
    ASSERT_GE(H5Oget_info_by_name2(f.id(), object.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT), 0) << object;
#endif
    addr = info.addr;
  }
  std::FILE* fp = std::fopen(file.c_str(), "r+b");
  ASSERT_NE(fp, nullptr);
  ASSERT_EQ(std::fseek(fp, long(addr), SEEK_SET), 0);
  ASSERT_EQ(std::fputc(0xEE, fp), 0xEE);
  std::fclose(fp);
  const h5::File f = h5::File::open(file);
  EXPECT_THROW(f.open_group(object), IoError) << object << " is still readable: the damage did not take";
}

TEST(ResultsWriter, RestartDropsTheProfilesOfTheStepsItDrops) {
  TempDir dir;
  write_four_outputs(dir.path(), tetrahedron());
  ResultsWriter w = ResultsWriter::reopen(dir.path(), 0.15);
  EXPECT_FALSE(w.run_file_rebuilt()) << "nothing was damaged: trimmed in place";
  const h5::File f = h5::File::open(dir / "run.h5");
  EXPECT_EQ(f.open_group("profiles").children(), (std::vector<std::string>{"000000", "000001"}));
}

// A run killed while it wrote its last output left a damaged step and profile after the restart
// time (seen in a SIGKILL test: the restart then failed to unlink /profiles/000001). The restart
// rebuilds run.h5 without them, and the continued run writes over their names.
TEST(ResultsWriter, RestartRebuildsARunFileWithDamagedObjectsAfterTheRestartTime) {
  TempDir dir;
  const SurfaceMesh mesh = tetrahedron();
  write_four_outputs(dir.path(), mesh);
  damage_object_header(dir / "run.h5", "/steps/000003");
  damage_object_header(dir / "run.h5", "/profiles/000003");
  ResultsWriter w = ResultsWriter::reopen(dir.path(), 0.2, {{"command_line", "capsflow run --restart"}});
  EXPECT_TRUE(w.run_file_rebuilt());
  EXPECT_EQ(w.num_steps(), 3u);
  {
    const h5::File f = h5::File::open(dir / "run.h5");
    EXPECT_EQ(f.open_group("steps").children(), (std::vector<std::string>{"000000", "000001", "000002"}));
    EXPECT_EQ(f.open_group("profiles").children(), (std::vector<std::string>{"000000", "000001", "000002"}));
    // What is kept is copied exactly (bit for bit: the same doubles).
    EXPECT_EQ(f.read_matrix<double>("steps/000002/positions"), mesh.vertices * 1.2);
    EXPECT_EQ(f.read_matrix<double>("profiles/000002/x1x3/points"), mesh.vertices * 1.2);
    EXPECT_EQ(f.read_matrix<int>("mesh/triangles"), mesh.triangles);
    EXPECT_EQ(f.open_group("metadata").read_string("command_line"), "capsflow run scene.toml -o out");
    EXPECT_EQ(f.open_group("metadata/restarts/0").attribute_double("t_restart"), 0.2);
    EXPECT_EQ(f.open_group("steps").attribute_string("csv_header"), "t,D12");
  }
  write_test_step(w, mesh, 0.30000000000000004);
  w.write_profiles({{"x1x3", mesh.vertices, Eigen::VectorXi::LinSpaced(2, 0, 4)}});
  w.append_row({{"t", 0.30000000000000004}, {"D12", 0.03}});
  const h5::File f = h5::File::open(dir / "run.h5");
  EXPECT_EQ(f.open_group("steps/000003").attribute_double("time"), 0.30000000000000004);
  EXPECT_EQ(f.open_group("profiles").children().size(), 4u);
  EXPECT_EQ(read_text(dir / "timeseries.csv"), "t,D12\n0,0\n0.1,0.01\n0.2,0.02\n0.30000000000000004,0.03\n");
}

// A damaged step the restart would keep is data it cannot give back: refused, naming it, and
// run.h5 is left as it was.
TEST(ResultsWriter, RestartRefusesARunFileDamagedBeforeTheRestartTime) {
  TempDir dir;
  write_four_outputs(dir.path(), tetrahedron());
  damage_object_header(dir / "run.h5", "/steps/000001");
  const std::string before = read_text(dir / "run.h5");
  try {
    ResultsWriter::reopen(dir.path(), 0.2);
    ADD_FAILURE() << "reopen accepted a run.h5 whose kept step is damaged";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("/steps/000001 was written before the restart time and cannot be read"),
              std::string::npos) << e.what();
  }
  EXPECT_EQ(read_text(dir / "run.h5"), before);
}

// Several capsules in one union mesh (MeshParts). A tetrahedron (4 nodes, 4 triangles) and an
// octahedron (6 nodes, 8 triangles) rather than two equal surfaces: node and element offsets then
// differ ({0, 4, 10} and {0, 4, 12}), so a mix-up of the two would show.
struct TwoCapsules {
  SurfaceMesh tetra = tetrahedron();
  SurfaceMesh octa;
  SurfaceMesh union_mesh;
  MeshParts parts{{0, 4, 10}, {0, 4, 12}};

  TwoCapsules() {
    octa.vertices.resize(6, 3);
    octa.vertices << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
    octa.vertices.col(0).array() += 5;  // disjoint from the tetrahedron
    octa.triangles.resize(8, 3);
    octa.triangles << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
    union_mesh.vertices.resize(10, 3);
    union_mesh.vertices << tetra.vertices, octa.vertices;
    union_mesh.triangles.resize(12, 3);
    // The union's triangles hold global node indices: the octahedron's nodes follow the 4 of the
    // tetrahedron.
    union_mesh.triangles << tetra.triangles, (octa.triangles.array() + 4).matrix();
  }
};

// The HDF5 file type of a dataset equals `type` (checked with the C API: the h5 layer converts
// on read, so reading back would not show a wrong width).
bool dataset_type_is(const std::filesystem::path& file, const char* dataset, hid_t type) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t d = H5Dopen2(f, dataset, H5P_DEFAULT);
  const hid_t t = H5Dget_type(d);
  const bool same = t >= 0 && H5Tequal(t, type) > 0;
  H5Tclose(t);
  H5Dclose(d);
  H5Fclose(f);
  return same;
}

std::vector<std::int64_t> int64_vector(const h5::File& f, const std::string& name) {
  const Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1> v = f.read_vector<std::int64_t>(name);
  return {v.data(), v.data() + v.size()};
}

// What one XDMF HyperSlab selects: its "start stride count" values and the dataset it reads.
struct Slab {
  std::string values, dataset;
  bool operator==(const Slab& o) const { return values == o.values && dataset == o.dataset; }
};
std::ostream& operator<<(std::ostream& os, const Slab& s) {
  return os << "{" << s.values << " of " << s.dataset << "}";
}

// The slabs of each grid named "capsule <k>", in document order, keyed by the grid's name.
std::vector<std::pair<std::string, std::vector<Slab>>> capsule_grids(const std::string& xml) {
  std::vector<std::pair<std::string, std::vector<Slab>>> grids;
  const std::regex grid("<Grid Name=\"(capsule [0-9]+)\" GridType=\"Uniform\">");
  const std::regex slab(
      "<DataItem Dimensions=\"3 [12]\" Format=\"XML\">([^<]*)</DataItem>\\s*"
      "<DataItem[^>]*>run\\.h5:([^<]+)</DataItem>");
  for (std::sregex_iterator it(xml.begin(), xml.end(), grid), end; it != end; ++it) {
    const std::size_t from = std::size_t(it->position(0));
    const std::string body = xml.substr(from, xml.find("</Grid>", from) - from);
    std::vector<Slab> slabs;
    for (std::sregex_iterator s(body.begin(), body.end(), slab); s != end; ++s) {
      slabs.push_back({(*s)[1].str(), (*s)[2].str()});
    }
    grids.emplace_back((*it)[1].str(), std::move(slabs));
  }
  return grids;
}

// Step t of the two capsules: the union's positions scaled by (1 + t), a vector and a scalar field
// with the union's rows.
void write_union_step(ResultsWriter& w, const TwoCapsules& c, double t) {
  const Points x = c.union_mesh.vertices * (1 + t);
  w.write_step(t, x, {{"velocity", x * 0.5}, {"tension", Eigen::VectorXd::Constant(10, t)}});
}

TEST(ResultsWriter, SeveralCapsulesAreRecordedUnderMeshParts) {
  TempDir dir;
  const TwoCapsules c;
  ResultsWriter w(dir.path(), c.union_mesh, metadata(), c.parts);
  for (double t : {0.0, 0.5}) write_union_step(w, c, t);
  EXPECT_EQ(w.parts().nodes, (std::vector<std::int64_t>{0, 4, 10}));  // as given
  EXPECT_EQ(w.parts().elements, (std::vector<std::int64_t>{0, 4, 12}));
  const std::filesystem::path run = dir / "run.h5";
  const h5::File f = h5::File::open(run);
  EXPECT_EQ(f.open_group("mesh/parts").children(),
            (std::vector<std::string>{"element_offsets", "local_triangles", "node_offsets"}));
  // K + 1 = 3 offsets each: the tetrahedron's 4 nodes and 4 triangles, then the octahedron's 6 and 8.
  EXPECT_EQ(int64_vector(f, "mesh/parts/node_offsets"), (std::vector<std::int64_t>{0, 4, 10}));
  EXPECT_EQ(int64_vector(f, "mesh/parts/element_offsets"), (std::vector<std::int64_t>{0, 4, 12}));
  // Offsets int64 (any mesh size), local triangles int32 like /mesh/triangles.
  EXPECT_TRUE(dataset_type_is(run, "/mesh/parts/node_offsets", H5T_STD_I64LE));
  EXPECT_TRUE(dataset_type_is(run, "/mesh/parts/element_offsets", H5T_STD_I64LE));
  EXPECT_TRUE(dataset_type_is(run, "/mesh/parts/local_triangles", H5T_STD_I32LE));
  // Each capsule's triangles numbered from its own first node: the two meshes as they were
  // built, before the octahedron's were shifted by the tetrahedron's 4 nodes.
  const h5::RowMatrixXi local = f.read_matrix<int>("mesh/parts/local_triangles");
  ASSERT_EQ(local.rows(), 12);
  EXPECT_EQ(h5::RowMatrixXi(local.topRows(4)), h5::RowMatrixXi(c.tetra.triangles));
  EXPECT_EQ(h5::RowMatrixXi(local.bottomRows(8)), h5::RowMatrixXi(c.octa.triangles));
  // The union itself is unchanged: global indices, all nodes.
  EXPECT_EQ(f.read_matrix<int>("mesh/triangles"), h5::RowMatrixXi(c.union_mesh.triangles));
  EXPECT_EQ(f.read_matrix<double>("mesh/reference_positions"), h5::RowMatrixXd(c.union_mesh.vertices));
  // Rows [4, 10) of a step's positions are the octahedron (scaled by 1 + t = 1.5): what capsule
  // 2's grid shows.
  EXPECT_EQ(h5::RowMatrixXd(f.read_matrix<double>("steps/000001/positions").bottomRows(6)),
            h5::RowMatrixXd(c.octa.vertices * 1.5));
}

TEST(ResultsWriter, XdmfHasOneGridPerCapsuleOverItsRowsOfTheUnion) {
  TempDir dir;
  const TwoCapsules c;
  ResultsWriter w(dir.path(), c.union_mesh, metadata(), c.parts);
  for (double t : {0.0, 0.5}) write_union_step(w, c, t);
  const std::string xml = read_text(dir / "run.xmf");
  EXPECT_TRUE(tags_balanced(xml)) << xml;
  // One spatial collection per step, holding the step's time.
  EXPECT_EQ(all_matches(xml, std::regex("<Grid Name=\"(step_\\d+)\" GridType=\"Collection\" "
                                        "CollectionType=\"Spatial\">")),
            (std::vector<std::string>{"step_000000", "step_000001"}));
  EXPECT_EQ(all_matches(xml, std::regex("<Time Value=\"([^\"]*)\"/>")),
            (std::vector<std::string>{"0", "0.5"}));
  const auto grids = capsule_grids(xml);
  ASSERT_EQ(grids.size(), 4u) << xml;  // 2 steps × 2 capsules
  for (std::size_t i = 0; i < grids.size(); ++i) {
    const std::string step = i < 2 ? "/steps/000000/" : "/steps/000001/";
    const auto& [name, slabs] = grids[i];
    // Start, stride, count per dimension: the capsule's rows, every column. Capsule 1: triangles
    // and nodes from row 0, 4 of each; capsule 2: triangles from row 4 (8 of them), nodes from
    // row 4 (6 of them). The scalar is 1-D: one start, stride and count.
    const std::vector<Slab> expected =
        i % 2 == 0 ? std::vector<Slab>{{"0 0 1 1 4 3", "/mesh/parts/local_triangles"},
                                       {"0 0 1 1 4 3", step + "positions"},
                                       {"0 0 1 1 4 3", step + "velocity"},
                                       {"0 1 4", step + "tension"}}
                   : std::vector<Slab>{{"4 0 1 1 8 3", "/mesh/parts/local_triangles"},
                                       {"4 0 1 1 6 3", step + "positions"},
                                       {"4 0 1 1 6 3", step + "velocity"},
                                       {"4 1 6", step + "tension"}};
    EXPECT_EQ(name, i % 2 == 0 ? "capsule 1" : "capsule 2");  // 1-based, in part order
    EXPECT_EQ(slabs, expected) << name;
  }
  // Every HDF DataItem names a dataset of run.h5 with its full shape (the HyperSlab selects the
  // rows), as for one surface.
  const std::regex item("Format=\"HDF\" Dimensions=\"([0-9 ]+)\"[^>]*>run\\.h5:([^<]+)</DataItem>");
  const std::size_t items = check_data_items(xml, item, dir / "run.h5");
  EXPECT_EQ(items, 2u * 2u * 4u);  // steps × capsules × (topology, geometry, 2 fields)
}

// A restart reads the parts back from run.h5: the rewritten run.xmf keeps one grid per capsule,
// whether run.h5 is trimmed in place or rebuilt (H5Ocopy of /mesh) around a damaged step.
TEST(ResultsWriter, RestartKeepsOneGridPerCapsule) {
  for (const bool damage : {false, true}) {
    SCOPED_TRACE(damage ? "rebuilt" : "trimmed in place");
    TempDir dir;
    const TwoCapsules c;
    {
      ResultsWriter w(dir.path(), c.union_mesh, metadata(), c.parts);
      for (double t : {0.0, 0.5}) write_union_step(w, c, t);
    }
    if (damage) damage_object_header(dir / "run.h5", "/steps/000001");
    ResultsWriter w = ResultsWriter::reopen(dir.path(), 0.0);  // keeps the step at t = 0 only
    EXPECT_EQ(w.run_file_rebuilt(), damage);
    EXPECT_EQ(w.num_steps(), 1u);
    EXPECT_EQ(w.parts().nodes, c.parts.nodes);  // read back from /mesh/parts
    EXPECT_EQ(w.parts().elements, c.parts.elements);
    const std::string xml = read_text(dir / "run.xmf");
    EXPECT_TRUE(tags_balanced(xml)) << xml;
    EXPECT_EQ(all_matches(xml, std::regex("<Time Value=\"([^\"]*)\"/>")), (std::vector<std::string>{"0"}));
    const auto grids = capsule_grids(xml);
    ASSERT_EQ(grids.size(), 2u) << xml;  // 1 step × 2 capsules
    EXPECT_EQ(grids[1].second.at(0), (Slab{"4 0 1 1 8 3", "/mesh/parts/local_triangles"}));
    {
      const h5::File f = h5::File::open(dir / "run.h5");
      EXPECT_EQ(int64_vector(f, "mesh/parts/node_offsets"), c.parts.nodes);
      EXPECT_EQ(h5::RowMatrixXi(f.read_matrix<int>("mesh/parts/local_triangles").bottomRows(8)),
                h5::RowMatrixXi(c.octa.triangles));
    }
    // The continued run adds the second capsule grid pair at the next step.
    write_union_step(w, c, 0.25);
    EXPECT_EQ(capsule_grids(read_text(dir / "run.xmf")).size(), 4u);
  }
}

TEST(ResultsWriter, RefusesPartsThatDoNotSplitTheMesh) {
  TempDir dir;
  const TwoCapsules c;
  const auto refusal = [&](const SurfaceMesh& mesh, const MeshParts& parts) -> std::string {
    try {
      ResultsWriter(dir.path(), mesh, metadata(), parts);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  // The first capsule must start at node 0: nothing may lie outside every capsule.
  EXPECT_EQ(refusal(c.union_mesh, {{1, 4, 10}, {0, 4, 12}}),
            "ResultsWriter: mesh parts: node offsets start at 1, not 0");
  // The last offset is the union's count (12 triangles).
  EXPECT_EQ(refusal(c.union_mesh, {{0, 4, 10}, {0, 4, 11}}),
            "ResultsWriter: mesh parts: element offsets end at 11, not at the mesh's 12 triangles");
  // Triangle 5 (capsule 2's second) made to use node 0, the tetrahedron's: it crosses capsules,
  // and would have no local index in capsule 2.
  SurfaceMesh crossing = c.union_mesh;
  crossing.triangles(5, 0) = 0;
  EXPECT_EQ(refusal(crossing, c.parts),
            "ResultsWriter: mesh parts: triangle 5 of capsule 2 (triangles [4, 12)) uses node 0, "
            "outside the capsule's nodes [4, 10)");
  // Refused before anything is written.
  EXPECT_TRUE(listing(dir.path()).empty());
}

// One part (the whole mesh) is one surface: the run.h5 layout and run.xmf of a run without parts.
TEST(ResultsWriter, OnePartIsTheLayoutOfOneSurface) {
  TempDir with_part, without;
  const SurfaceMesh mesh = tetrahedron();
  ResultsWriter a(with_part.path(), mesh, metadata(), MeshParts{{0, 4}, {0, 4}});
  ResultsWriter b(without.path(), mesh, metadata());
  write_test_step(a, mesh, 0.0);
  write_test_step(b, mesh, 0.0);
  EXPECT_FALSE(h5::File::open(with_part / "run.h5").exists("mesh/parts"));
  EXPECT_EQ(h5::File::open(with_part / "run.h5").open_group("mesh").children(),
            (std::vector<std::string>{"reference_positions", "triangles"}));
  EXPECT_EQ(read_text(with_part / "run.xmf"), read_text(without / "run.xmf"));
  // Both report one part spanning the mesh's 4 nodes and 4 triangles.
  EXPECT_EQ(a.parts().nodes, (std::vector<std::int64_t>{0, 4}));
  EXPECT_EQ(b.parts().elements, (std::vector<std::int64_t>{0, 4}));
}

TEST(TimeseriesCsv, RestoreRowsChangesNothingWhenNoRowIsMissing) {
  TempDir dir;
  const std::filesystem::path csv = dir / "timeseries.csv";
  write_text(csv, "t,D12\n0,0\n0.1,0.5\n");
  EXPECT_EQ(TimeseriesCsv::restore_rows(csv, "t,D12", {"0,0", "0.1,0.5"}), 0u);
  EXPECT_EQ(TimeseriesCsv::restore_rows(csv, "t,D12", {}), 0u);  // a run.h5 of an older capsflow
  EXPECT_EQ(read_text(csv), "t,D12\n0,0\n0.1,0.5\n");
  EXPECT_EQ(TimeseriesCsv::restore_rows(csv, "t,D12", {"0,0", "0.1,0.5", "0.2,0.7"}), 1u);
  EXPECT_EQ(read_text(csv), "t,D12\n0,0\n0.1,0.5\n0.2,0.7\n");
}

TEST(ResultsWriter, RestartBeforeTheFirstStepEmptiesTheSeries) {
  TempDir dir;
  const SurfaceMesh mesh = tetrahedron();
  {
    ResultsWriter w(dir.path(), mesh, metadata());
    write_test_step(w, mesh, 0.5);
    w.append_row({{"t", 0.5}});
  }
  ResultsWriter w = ResultsWriter::reopen(dir.path(), 0.25);
  EXPECT_EQ(w.num_steps(), 0u);
  EXPECT_FALSE(std::filesystem::exists(dir / "run.xmf"));  // no empty collection for ParaView
  EXPECT_EQ(read_text(dir / "timeseries.csv"), "t\n");
  EXPECT_FALSE(h5::File::open(dir / "run.h5").exists("metadata/restarts"));  // no metadata given
  write_test_step(w, mesh, 0.5);
  EXPECT_EQ(count_uniform_grids(read_text(dir / "run.xmf")), 1u);
}

TEST(ResultsWriter, WritesWhileAnotherProcessHoldsRunFileOpen) {
  // ParaView keeps run.h5 open between reloads; HDF5 >= 1.10 file locking must not stop the run.
  TempDir dir;
  const SurfaceMesh mesh = tetrahedron();
  ResultsWriter w(dir.path(), mesh, metadata());
  write_test_step(w, mesh, 0.0);
  int ready[2], done[2];
  ASSERT_EQ(pipe(ready), 0);
  ASSERT_EQ(pipe(done), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // the "reader": opens read-only, reports, waits to be told to exit
    const hid_t f = H5Fopen((dir / "run.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    char c = f >= 0 ? 'y' : 'n';
    if (write(ready[1], &c, 1) != 1) _exit(2);
    if (read(done[0], &c, 1) != 1) _exit(2);
    _exit(0);
  }
  char c = 0;
  ASSERT_EQ(read(ready[0], &c, 1), 1);
  EXPECT_EQ(c, 'y');
  EXPECT_NO_THROW(write_test_step(w, mesh, 0.1));
  c = 'q';
  EXPECT_EQ(write(done[1], &c, 1), 1);
  int status = 0;
  waitpid(child, &status, 0);
  for (int fd : {ready[0], ready[1], done[0], done[1]}) close(fd);
  EXPECT_EQ(w.num_steps(), 2u);
  EXPECT_EQ(h5::File::open(dir / "run.h5").open_group("steps").children().size(), 2u);
}

}  // namespace
}  // namespace capsflow::io
