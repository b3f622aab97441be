// docs/scene-and-output.md against what a run writes: the columns of timeseries.csv (§3.4) in the
// order of the file.
#include <gtest/gtest.h>

#include <sstream>

#include "run_capsflow.hpp"

using namespace capsflow_test;

namespace {

// The column names of the docs' §3.4 table, in its order: the backticked names of each row's first cell.
std::vector<std::string> documented_columns() {
  const std::string docs = slurp(fs::path(CAPSFLOW_SOURCE_DIR) / "docs" / "scene-and-output.md");
  const auto begin = docs.find("### 3.4"), end = docs.find("\n### ", begin + 1);
  std::istringstream lines(docs.substr(begin, end - begin));
  std::vector<std::string> names;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("| `", 0) != 0) continue;  // table rows whose first cell names columns
    const std::string cell = line.substr(1, line.find(" |", 1) - 1);
    for (auto a = cell.find('`'); a != std::string::npos; a = cell.find('`', cell.find('`', a + 1) + 1))
      names.push_back(cell.substr(a + 1, cell.find('`', a + 1) - a - 1));
  }
  return names;
}

}  // namespace

// §3.4 listed wall_seconds after the health columns; the file has it after
// steady_measure. A run with fluid.verify_every > 0 and fluid.viscosity_ratio ≠ 1 writes every
// documented column.
TEST(DocsOutput, CsvColumnsAreListedInTheOrderOfTheFile) {
  TempDir d("docs");
  ASSERT_EQ(run("--set mesh.level=1 --set wall.model=membrane --set flow.ca_s=0.2 --set time.t_end=0.01 "
                "--set fluid.verify_every=1 --set fluid.viscosity_ratio=2",
                d.path / "run"),
            0)
      << slurp(d.path.string() + "/run.log");
  std::ifstream csv(d.path / "run" / "timeseries.csv");
  std::string header;
  std::getline(csv, header);
  std::vector<std::string> columns;
  std::istringstream hs(header);
  for (std::string c; std::getline(hs, c, ',');) columns.push_back(c);
  EXPECT_EQ(documented_columns(), columns);
}

// `capsflow info --keys` prints the key table; the docs' tables of §2.2–2.7 are pasted from it
// (tests/core/scene/test_scene_keys.cpp checks them against the table itself).
TEST(DocsOutput, InfoKeysPrintsTheDocsKeyTables) {
  TempDir d("docs");
  const Result r = capsflow("info --keys", d.path);
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string docs = slurp(fs::path(CAPSFLOW_SOURCE_DIR) / "docs" / "scene-and-output.md");
  for (const std::string section : {"mesh", "wall", "flow", "time", "fluid", "output"}) {
    const auto h = docs.find("`[" + section + "]`\n"), a = docs.find("\n|", h) + 1, b = docs.find("\n\n", a);
    const std::string table = docs.substr(a, b - a + 1);
    EXPECT_NE(r.out.find("[" + section + "]\n" + table), std::string::npos) << section << ":\n" << table << "\nin:\n" << r.out;
  }
}
