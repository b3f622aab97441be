// output_folder: refuses non-empty folders without overwrite (touching nothing), removes only
// capsflow's own files with overwrite, reports unwritable paths up front.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

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
                        "checkpoint.prev.h5", "run.xmf.tmp.4242", "notes.txt", "run.h5.bak",
                        "analysis.py"}) {
    write_text(dir / f, "x");
  }
  // Not in the manifest (io/manifest.hpp): capsflow never writes these. `log` was removed once,
  // e.g. the log of `capsflow run -o out --overwrite > out/log 2>&1` itself.
  for (const char* f : {"log", "capsflow.log", "checkpoint_backup_from_cluster.h5", "checkpoint.h5.tmp.x"}) {
    write_text(dir / f, std::string("the user's ") + f);
  }
  std::filesystem::create_directory(dir / "figures");
  write_text(dir / "figures/run.h5", "a user's file inside a sub-folder");
  const PreparedFolder p = prepare_output_folder(dir.path(), true);
  EXPECT_EQ(listing(dir.path()),
            (std::vector<std::string>{"analysis.py", "capsflow.log", "checkpoint.h5.tmp.x",
                                      "checkpoint_backup_from_cluster.h5", "figures", "log", "notes.txt",
                                      "run.h5.bak"}));
  EXPECT_EQ(read_text(dir / "figures/run.h5"),
            "a user's file inside a sub-folder");  // no recursion
  EXPECT_EQ(read_text(dir / "log"), "the user's log");
  EXPECT_EQ(read_text(dir / "checkpoint_backup_from_cluster.h5"), "the user's checkpoint_backup_from_cluster.h5");
  EXPECT_EQ(p.removed.size(), 7u);
  EXPECT_EQ(p.kept.size(), 8u);
}

TEST(OutputFolder, CapsflowNames) {
  EXPECT_TRUE(is_capsflow_output_name("checkpoint.h5"));
  EXPECT_TRUE(is_capsflow_output_name("checkpoint.prev.h5"));
  EXPECT_TRUE(is_capsflow_output_name("summary.json.tmp.17"));
  EXPECT_TRUE(is_capsflow_output_name(".capsflow-write-probe.17"));
  EXPECT_FALSE(is_capsflow_output_name("checkpoint_000010.h5"));  // exact names only
  EXPECT_FALSE(is_capsflow_output_name("checkpoint_backup_from_cluster.h5"));
  EXPECT_FALSE(is_capsflow_output_name("log"));
  EXPECT_FALSE(is_capsflow_output_name("capsflow.log"));
  EXPECT_FALSE(is_capsflow_output_name("summary.json.tmp.x"));
  EXPECT_FALSE(is_capsflow_output_name("notes.txt.tmp.17"));
  EXPECT_FALSE(is_capsflow_output_name("checkpoint.h5.txt"));
  EXPECT_FALSE(is_capsflow_output_name("my_run.h5"));
  EXPECT_TRUE(is_capsflow_output_name("channel.h5"));   // a channel's wall (docs/channel.md §5)
  EXPECT_TRUE(is_capsflow_output_name("channel.xmf"));
  EXPECT_EQ(output_manifest().size(), 8u);
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

TEST(OutputFolder, RestartRemovesStaleTemporariesOfDeadProcessesOnly) {
  TempDir dir;
  // A pid above pid_max never runs; our own pid certainly does.
  long pid_max = 4194304;
  std::ifstream("/proc/sys/kernel/pid_max") >> pid_max;
  const std::string dead = std::to_string(pid_max + 1), alive = std::to_string(::getpid());
  for (const std::string& f : {"run.xmf.tmp." + dead, "checkpoint.h5.tmp." + dead, "summary.json.tmp." + alive,
                               "notes.txt.tmp." + dead, std::string("run.h5")}) {
    write_text(dir / f, "x");
  }
  const PreparedFolder p = open_output_folder_for_restart(dir.path());
  EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"notes.txt.tmp." + dead, "run.h5", "summary.json.tmp." + alive}));
  EXPECT_EQ(p.removed.size(), 2u);
}

TEST(OutputFolder, ItsRefusalsAreIoErrors) {
  TempDir dir;
  write_text(dir / "run.h5", "previous results");
  EXPECT_THROW(prepare_output_folder(dir.path(), false), IoError);  // Python: OSError
  EXPECT_THROW(open_output_folder_for_restart(dir / "absent"), IoError);
}

}  // namespace
}  // namespace capsflow::io
