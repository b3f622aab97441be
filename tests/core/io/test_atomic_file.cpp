// atomic_file: content replaced whole, no temporary left behind, errors name the path.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "capsflow/core/io/atomic_file.hpp"
#include "temp_dir.hpp"

namespace capsflow::io {
namespace {
using testing::listing;
using testing::read_text;
using testing::TempDir;
using testing::write_text;

TEST(AtomicFile, ReplacesContentAndLeavesNoTemporary) {
  TempDir dir;
  const auto target = dir / "summary.json";
  write_text(target, "old content that is longer than the new one\n");
  write_file_atomically(target, "{\"t\": 1}\n");
  EXPECT_EQ(read_text(target), "{\"t\": 1}\n");  // exact: the whole file is the new content
  EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"summary.json"});  // no *.tmp.<pid>
}

TEST(AtomicFile, CreatesAMissingFileAndHandlesEmptyContent) {
  TempDir dir;
  write_file_atomically(dir / "a.txt", "");
  EXPECT_TRUE(std::filesystem::exists(dir / "a.txt"));
  EXPECT_EQ(std::filesystem::file_size(dir / "a.txt"), 0u);
}

TEST(AtomicFile, TemporaryIsASiblingNamedWithThePid) {
  const auto tmp = temporary_sibling("/some/dir/run.xmf");
  EXPECT_EQ(tmp.parent_path(), "/some/dir");  // same folder: rename() stays on one file system
  EXPECT_EQ(tmp.filename().string(), "run.xmf.tmp." + std::to_string(::getpid()));
}

TEST(AtomicFile, ErrorNamesThePathAndTheReason) {
  TempDir dir;
  write_text(dir / "plain", "x");
  const auto target = dir / "plain" / "summary.json";  // parent is a regular file
  try {
    write_file_atomically(target, "x");
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find((dir / "plain").string()), std::string::npos) << msg;  // names the path
    EXPECT_NE(msg.find("Not a directory"), std::string::npos) << msg;         // strerror(ENOTDIR)
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;                      // one line
  }
}

TEST(AtomicFile, FailingWriterLeavesTargetAndNoTemporary) {
  TempDir dir;
  const auto target = dir / "checkpoint.h5";
  write_text(target, "good");
  EXPECT_THROW(replace_file_atomically(target,
                                       [](const std::filesystem::path& tmp) {
                                         write_text(tmp, "half");
                                         throw std::runtime_error("disk full");
                                       }),
               std::runtime_error);
  EXPECT_EQ(read_text(target), "good");  // the last good file survives a failed write
  EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"checkpoint.h5"});
}

}  // namespace
}  // namespace capsflow::io
