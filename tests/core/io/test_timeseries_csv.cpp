// timeseries.csv: header from the first row, exact numbers, restart truncation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "capsflow/core/io/timeseries_csv.hpp"
#include "temp_dir.hpp"

namespace capsflow::io {
namespace {
using testing::read_text;
using testing::TempDir;
using testing::write_text;

TEST(TimeseriesCsv, HeaderFromFirstRowAndRowsFlushed) {
  TempDir dir;
  const auto path = dir / "timeseries.csv";
  TimeseriesCsv csv(path);
  csv.append_row({{"t", 0.0}, {"D12", 0.1}, {"area", 12.566370614359172}});
  // Read while the writer is still open: the row must already be on disk (flushed).
  EXPECT_EQ(read_text(path), "t,D12,area\n0,0.1,12.566370614359172\n");
  csv.append_row({{"t", 0.1}, {"D12", -1e-20}, {"area", NAN}});
  EXPECT_EQ(read_text(path), "t,D12,area\n0,0.1,12.566370614359172\n0.1,-1e-20,\n");  // undefined: empty, never "nan"
}

TEST(TimeseriesCsv, NumbersReadBackBitForBit) {
  TempDir dir;
  const auto path = dir / "timeseries.csv";
  const double values[] = {1.0 / 3.0, 0.30000000000000004, 6.02214076e23, 5e-324, -2.5};
  {
    TimeseriesCsv csv(path);
    for (double v : values) csv.append_row({{"t", v}});
  }
  const std::string text = read_text(path);
  std::size_t pos = text.find('\n') + 1;
  for (double v : values) {
    const std::size_t nl = text.find('\n', pos);
    // Exact: the printed decimal must parse back to the identical double.
    EXPECT_EQ(std::strtod(text.substr(pos, nl - pos).c_str(), nullptr), v);
    pos = nl + 1;
  }
}

TEST(TimeseriesCsv, RejectsChangedColumnsAndBadNames) {
  TempDir dir;
  TimeseriesCsv csv(dir / "timeseries.csv");
  csv.append_row({{"t", 0.0}, {"D12", 0.0}});
  EXPECT_THROW(csv.append_row({{"t", 0.1}}), std::invalid_argument);
  EXPECT_THROW(csv.append_row({{"t", 0.1}, {"D13", 0.0}}), std::invalid_argument);
  TimeseriesCsv other(dir / "other.csv");
  EXPECT_THROW(other.append_row({{"a,b", 0.0}}), std::invalid_argument);
}

TEST(TimeseriesCsv, TruncateAfterKeepsHeaderAndEarlierRows) {
  TempDir dir;
  const auto path = dir / "timeseries.csv";
  // Last line incomplete, as a crash in the middle of a write leaves it.
  write_text(path, "step,t,D12\n0,0,0\n1,0.5,0.01\n2,1,0.02\n3,1.5,0.03\n4,2,0.0");
  EXPECT_EQ(TimeseriesCsv::truncate_after(path, 1.0), 1u);  // row t=1.5 (the partial line is gone)
  EXPECT_EQ(read_text(path), "step,t,D12\n0,0,0\n1,0.5,0.01\n2,1,0.02\n");  // t = 1 kept: <=
  TimeseriesCsv csv(path);  // a restarted run adopts the header and appends
  EXPECT_EQ(csv.columns(), (std::vector<std::string>{"step", "t", "D12"}));
  csv.append_row({{"step", 3}, {"t", 1.5}, {"D12", 0.031}});
  EXPECT_EQ(read_text(path), "step,t,D12\n0,0,0\n1,0.5,0.01\n2,1,0.02\n3,1.5,0.031\n");
  EXPECT_THROW(csv.append_row({{"t", 2.0}}), std::invalid_argument);  // header is enforced
}

TEST(TimeseriesCsv, IncompleteLastLineIsCutBeforeAppending) {
  TempDir dir;
  const auto path = dir / "timeseries.csv";
  write_text(path, "t,D12\n0,0\n0.1,0.0");  // killed in the middle of a row
  TimeseriesCsv csv(path);
  csv.append_row({{"t", 0.1}, {"D12", 0.5}});
  EXPECT_EQ(read_text(path), "t,D12\n0,0\n0.1,0.5\n");
}

TEST(TimeseriesCsv, TruncateMissingFileIsANoOp) {
  TempDir dir;
  EXPECT_EQ(TimeseriesCsv::truncate_after(dir / "absent.csv", 1.0), 0u);
  EXPECT_FALSE(std::filesystem::exists(dir / "absent.csv"));
}

}  // namespace
}  // namespace capsflow::io
