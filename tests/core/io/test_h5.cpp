// h5: dataset and attribute round trips, existence and listing, errors as exceptions.
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <cmath>
#include <csignal>
#include <limits>

#include "capsflow/core/io/h5.hpp"
#include "capsflow/core/types.hpp"
#include "temp_dir.hpp"

namespace capsflow::io {
namespace {
using testing::TempDir;

TEST(H5, MatrixVectorAndStringRoundTripsAreExact) {
  TempDir dir;
  const auto path = dir / "a.h5";
  Points x(4, 3);
  x << 0.1, -2.5, 1e-300, std::nextafter(1.0, 2.0), 3, 4, 5, 6, 7, -0.0, 1e300, M_PI;
  Triangles tri(2, 3);
  tri << 0, 1, 2, 2, 3, 0;
  Eigen::MatrixXd colmajor(2, 3);  // column-major input must still come back in (row, col) order
  colmajor << 1, 2, 3, 4, 5, 6;
  Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(5, 0.0, 1.0);
  Eigen::VectorXi vi(3);
  vi << -7, 0, 2147483647;
  const std::string text = "scene = \"ünïcode\"\n[mesh]\nlevel = 4\n";
  {
    h5::File f = h5::File::create(path);
    f.write_matrix("mesh/positions", x);  // intermediate group created on the fly
    f.write_matrix("mesh/triangles", tri);
    f.write_matrix("cm", colmajor);
    f.write_vector("v", v);
    f.write_vector("vi", vi);
    f.write_vector("empty", Eigen::VectorXd());
    f.write_string("text", text);
    f.write_string("empty_text", "");
    f.close();
  }
  h5::File f = h5::File::open(path);
  // Exact equality: float64 stored and read back without conversion.
  EXPECT_EQ(f.read_matrix<double>("mesh/positions"), h5::RowMatrixXd(x));
  EXPECT_EQ(f.read_matrix<int>("mesh/triangles"), h5::RowMatrixXi(tri));
  EXPECT_EQ(f.read_matrix<double>("cm"), h5::RowMatrixXd(colmajor));
  EXPECT_EQ(f.read_vector<double>("v"), v);
  EXPECT_EQ(f.read_vector<int>("vi"), vi);
  EXPECT_EQ(f.read_vector<double>("empty").size(), 0);
  EXPECT_EQ(f.read_string("text"), text);
  EXPECT_EQ(f.read_string("empty_text"), "");
  EXPECT_EQ(f.shape("mesh/positions"), (std::vector<hsize_t>{4, 3}));  // row-major [rows, cols]
  EXPECT_EQ(f.shape("v"), (std::vector<hsize_t>{5}));                  // vectors are 1-D
}

TEST(H5, AttributesRoundTripAndReplace) {
  TempDir dir;
  const auto path = dir / "a.h5";
  {
    h5::File f = h5::File::create(path);
    h5::Group g = f.create_group("steps/000001");
    g.set_attribute("time", 0.30000000000000004);
    g.set_attribute("count", std::int64_t{1} << 40);
    g.set_attribute("small", 3);
    g.set_attribute("name", "capsule");
    g.set_attribute("name", std::string("replaced"));  // setting again replaces
    f.set_attribute("nan", std::numeric_limits<double>::quiet_NaN());
  }
  h5::File f = h5::File::open(path);
  h5::Group g = f.open_group("steps/000001");
  EXPECT_EQ(g.attribute_double("time"), 0.30000000000000004);  // exact round trip
  EXPECT_EQ(g.attribute_int("count"), std::int64_t{1} << 40);  // int64, not truncated to 32 bits
  EXPECT_EQ(g.attribute_int("small"), 3);
  EXPECT_EQ(g.attribute_string("name"), "replaced");
  EXPECT_TRUE(std::isnan(f.attribute_double("nan")));
  EXPECT_TRUE(g.has_attribute("time"));
  EXPECT_FALSE(g.has_attribute("nope"));
  EXPECT_EQ(g.attribute_names(), (std::vector<std::string>{"count", "name", "small", "time"}));
  EXPECT_EQ(g.path(), "/steps/000001");
}

TEST(H5, ExistenceListingAndRemoval) {
  TempDir dir;
  h5::File f = h5::File::create(dir / "a.h5");
  f.write_vector("b/x", Eigen::VectorXd::Zero(2));
  f.create_group("a");
  f.write_vector("c", Eigen::VectorXd::Zero(1));
  EXPECT_TRUE(f.exists("b/x"));
  EXPECT_FALSE(f.exists("b/y"));
  EXPECT_FALSE(f.exists("nope/deeper"));  // a missing intermediate group is "false", not an error
  EXPECT_TRUE(f.is_group("a"));
  EXPECT_FALSE(f.is_group("c"));
  EXPECT_EQ(f.children(), (std::vector<std::string>{"a", "b", "c"}));  // name order
  f.remove("b");
  EXPECT_EQ(f.children(), (std::vector<std::string>{"a", "c"}));
  f.write_vector("c", Eigen::VectorXd::Ones(4));  // writing replaces an existing dataset
  EXPECT_EQ(f.shape("c"), (std::vector<hsize_t>{4}));
}

TEST(H5, ErrorsNameFileAndObject) {
  TempDir dir;
  const auto path = dir / "a.h5";
  {
    h5::File f = h5::File::create(path);
    f.write_vector("v", Eigen::VectorXd::Zero(3));
  }
  h5::File f = h5::File::open(path);
  try {
    f.read_matrix<double>("missing");
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path.string()), std::string::npos) << msg;  // names the file
    EXPECT_NE(msg.find("/missing"), std::string::npos) << msg;     // and the object
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  EXPECT_THROW(f.read_matrix<double>("v"), std::runtime_error);  // rank 1 is not a matrix
  EXPECT_THROW(f.read_vector<int>("v"), std::runtime_error);     // float is not read as int
  EXPECT_THROW(f.attribute_double("none"), std::runtime_error);
  EXPECT_THROW(h5::File::open(dir / "absent.h5"), std::runtime_error);
  testing::write_text(dir / "text.h5", "this is not HDF5");
  EXPECT_THROW(h5::File::open(dir / "text.h5"), std::runtime_error);
}

TEST(H5, ReadOnlyFileRejectsWrites) {
  TempDir dir;
  { h5::File::create(dir / "a.h5"); }
  h5::File f = h5::File::open(dir / "a.h5", h5::File::Mode::read_only);
  EXPECT_THROW(f.write_vector("v", Eigen::VectorXd::Zero(1)), std::runtime_error);
}

TEST(H5, LibraryVersionLooksLikeMajorMinorRelease) {
  const std::string v = h5::library_version();
  EXPECT_EQ(std::count(v.begin(), v.end(), '.'), 2) << v;
}

TEST(H5, AFullDiskGivesOneLineWithTheSystemsReason) {
  // RLIMIT_FSIZE makes writes beyond the limit fail (EFBIG) exactly like a full disk, without
  // privileges. SIGXFSZ is ignored so that write() returns the error instead of killing us.
  TempDir dir;
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  rlimit small = old;
  small.rlim_cur = 64 * 1024;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string msg;
  try {
    h5::File f = h5::File::create(dir / "big.h5");
    f.write_matrix("x", Points::Ones(100000, 3));  // 2.4 MB
    f.close();
  } catch (const std::runtime_error& e) {
    msg = e.what();
  }
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  ASSERT_FALSE(msg.empty());
  // Was "file write failed: time = <ctime>\n, filename = ..., errno = 27, error message = 'File
  // too large', buf = 0x..., total write size = ...": two lines of internals.
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  EXPECT_NE(msg.find("big.h5"), std::string::npos) << msg;
  EXPECT_NE(msg.find(": File too large"), std::string::npos) << msg;
  EXPECT_EQ(msg.find("buf = "), std::string::npos) << msg;
}

}  // namespace
}  // namespace capsflow::io
