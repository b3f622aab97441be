// output_folder: refuses non-empty folders without overwrite (touching nothing), removes only
// capsflow's own files with overwrite, reports unwritable paths up front.
#include <gtest/gtest.h>

#include "capsflow/core/io/output_folder.hpp"
#include "temp_dir.hpp"

namespace capsflow::io {
namespace {
using testing::listing;
using testing::read_text;
using testing::TempDir;
using testing::write_text;

TEST(OutputFolder, CreatesMissingFolderWithParents) {
  TempDir dir;
  const auto out = dir / "a/b/run1";
  const PreparedFolder p = prepare_output_folder(out, false);
  EXPECT_TRUE(std::filesystem::is_directory(out));
  EXPECT_TRUE(std::filesystem::is_empty(out));  // the writability probe is removed again
  EXPECT_TRUE(p.removed.empty());
}

TEST(OutputFolder, AcceptsAnEmptyExistingFolder) {
  TempDir dir;
  EXPECT_NO_THROW(prepare_output_folder(dir.path(), false));
}

TEST(OutputFolder, RefusesNonEmptyFolderAndLeavesItUntouched) {
  TempDir dir;
  write_text(dir / "run.h5", "previous results");
  write_text(dir / "notes.txt", "mine");
  try {
    prepare_output_folder(dir.path(), false);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "output folder '" + dir.path().string() +
                  "' exists and is not empty; pass --overwrite to replace it");
  }
  EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"notes.txt", "run.h5"}));
  EXPECT_EQ(read_text(dir / "run.h5"), "previous results");  // not even truncated
}

TEST(OutputFolder, OverwriteRemovesOnlyCapsflowFiles) {
  TempDir dir;
  for (const char* f : {"run.h5", "run.xmf", "timeseries.csv", "summary.json", "checkpoint.h5",
                        "checkpoint.prev.h5", "log", "run.xmf.tmp.4242", "notes.txt", "run.h5.bak",
                        "analysis.py"}) {
    write_text(dir / f, "x");
  }
  std::filesystem::create_directory(dir / "figures");
  write_text(dir / "figures/run.h5", "a user's file inside a sub-folder");
  const PreparedFolder p = prepare_output_folder(dir.path(), true);
  EXPECT_EQ(listing(dir.path()),
            (std::vector<std::string>{"analysis.py", "figures", "notes.txt", "run.h5.bak"}));
  EXPECT_EQ(read_text(dir / "figures/run.h5"),
            "a user's file inside a sub-folder");  // no recursion
  EXPECT_EQ(p.removed.size(), 8u);
  EXPECT_EQ(p.kept.size(), 4u);
}

TEST(OutputFolder, CapsflowNames) {
  EXPECT_TRUE(is_capsflow_output_name("checkpoint.h5"));
  EXPECT_TRUE(is_capsflow_output_name("checkpoint_000010.h5"));
  EXPECT_TRUE(is_capsflow_output_name("summary.json.tmp.17"));
  EXPECT_FALSE(is_capsflow_output_name("summary.json.tmp.x"));
  EXPECT_FALSE(is_capsflow_output_name("checkpoint.h5.txt"));
  EXPECT_FALSE(is_capsflow_output_name("my_run.h5"));
}

TEST(OutputFolder, PathUnderARegularFileGivesOneLineError) {
  // Tests run as root, where permission bits are not enforced; a regular file as parent fails
  // for everyone.
  TempDir dir;
  write_text(dir / "plain", "x");
  const auto out = dir / "plain" / "run";
  try {
    prepare_output_folder(out, false);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("cannot create output folder '" + out.string() + "'"), std::string::npos)
        << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  EXPECT_EQ(read_text(dir / "plain"), "x");
}

TEST(OutputFolder, ARegularFileIsNotAFolder) {
  TempDir dir;
  write_text(dir / "plain", "x");
  EXPECT_THROW(prepare_output_folder(dir / "plain", true), std::runtime_error);
  EXPECT_THROW(open_output_folder_for_restart(dir / "plain"), std::runtime_error);
  EXPECT_EQ(read_text(dir / "plain"), "x");
}

TEST(OutputFolder, RestartModeKeepsEverything) {
  TempDir dir;
  write_text(dir / "run.h5", "results");
  EXPECT_NO_THROW(open_output_folder_for_restart(dir.path()));
  EXPECT_EQ(read_text(dir / "run.h5"), "results");
  EXPECT_THROW(open_output_folder_for_restart(dir / "missing"), std::runtime_error);
}

}  // namespace
}  // namespace capsflow::io
