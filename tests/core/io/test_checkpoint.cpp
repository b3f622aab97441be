// Checkpoints: bit-exact round trip, two-slot rotation, validation and damaged files.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "capsflow/core/io/checkpoint.hpp"
#include "capsflow/core/io/h5.hpp"
#include "temp_dir.hpp"

namespace capsflow::io {
namespace {
using testing::listing;
using testing::TempDir;

CheckpointState sample_state(double seed) {
  std::srand(unsigned(seed * 1000));
  CheckpointState s;
  s.step = 123456789012;  // beyond 32 bits
  s.t = 0.1 + seed;
  s.dt = 1e-4 / 3;  // not a short decimal: exercises exact storage
  s.positions = Points::Random(6, 3);
  s.reference_positions = Points::Random(6, 3);
  s.triangles.resize(8, 3);
  s.triangles << 0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1, 5, 2, 1, 5, 3, 2, 5, 4, 3, 5, 1, 4;
  s.wall_state = Eigen::VectorXd::Random(12);
  s.history = Eigen::MatrixXd::Random(7, 2);
  s.scene_toml = "# ünïcode comment\n[time]\ndt = 1e-4\n";
  s.scene_resolved = R"({"time": {"dt": 0.0001}})";
  s.version = "capsflow 0.1.0 (abc1234-dirty)";
  s.extra = R"({"next_output_t": 0.2})";
  return s;
}

void expect_identical(const CheckpointState& a, const CheckpointState& b) {
  // Exact (bit-for-bit) comparisons: a restart must reproduce an uninterrupted run.
  EXPECT_EQ(a.step, b.step);
  EXPECT_EQ(std::memcmp(&a.t, &b.t, sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(&a.dt, &b.dt, sizeof(double)), 0);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.reference_positions, b.reference_positions);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.wall_state, b.wall_state);
  EXPECT_EQ(a.history, b.history);
  EXPECT_EQ(a.scene_toml, b.scene_toml);
  EXPECT_EQ(a.scene_resolved, b.scene_resolved);
  EXPECT_EQ(a.version, b.version);
  EXPECT_EQ(a.extra, b.extra);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Checkpoint, RoundTripIsBitForBit) {
  TempDir dir;
  const CheckpointState s = sample_state(0.5);
  write_checkpoint(dir / "checkpoint.h5", s);
  expect_identical(read_checkpoint(dir / "checkpoint.h5"), s);
  EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"checkpoint.h5"});  // no temporary
}

TEST(Checkpoint, EmptyOpaqueParts) {
  TempDir dir;
  CheckpointState s = sample_state(0.5);
  s.wall_state.resize(0);  // membrane model: no wall state
  s.history.resize(0, 0);
  s.extra.clear();
  write_checkpoint(dir / "checkpoint.h5", s);
  expect_identical(read_checkpoint(dir / "checkpoint.h5"), s);
}

TEST(Checkpoint, PreviousCheckpointIsKept) {
  TempDir dir;
  const auto path = dir / "checkpoint.h5";
  EXPECT_EQ(previous_checkpoint_path(path), dir / "checkpoint.prev.h5");
  write_checkpoint(path, sample_state(1));
  write_checkpoint(path, sample_state(2));
  EXPECT_EQ(read_checkpoint(path).t, sample_state(2).t);  // exact: same double
  EXPECT_EQ(read_checkpoint(dir / "checkpoint.prev.h5").t, sample_state(1).t);
  EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"checkpoint.h5", "checkpoint.prev.h5"}));
  EXPECT_EQ(find_latest_checkpoint(dir.path()), path);
}

TEST(Checkpoint, TruncatedFileIsRejectedNamingTheFile) {
  TempDir dir;
  const auto path = dir / "checkpoint.h5";
  write_checkpoint(path, sample_state(1));
  write_checkpoint(path, sample_state(2));
  std::filesystem::resize_file(path, std::filesystem::file_size(path) / 2);  // killed mid-copy
  const std::string msg = error_of([&] { read_checkpoint(path); });
  EXPECT_EQ(msg.rfind("checkpoint '" + path.string() + "': ", 0), 0u) << msg;  // names the file
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;                         // one line
  // --resume falls back to the previous slot.
  EXPECT_EQ(find_latest_checkpoint(dir.path()), dir / "checkpoint.prev.h5");
}

TEST(Checkpoint, GarbageAndForeignFilesAreRejected) {
  TempDir dir;
  testing::write_text(dir / "garbage.h5", std::string(4096, 'x'));
  EXPECT_NE(error_of([&] { read_checkpoint(dir / "garbage.h5"); }).find("not a readable HDF5 file"),
            std::string::npos);
  { h5::File::create(dir / "run.h5").write_vector("v", Eigen::VectorXd::Zero(1)); }
  EXPECT_NE(error_of([&] { read_checkpoint(dir / "run.h5"); }).find("not a capsflow checkpoint"),
            std::string::npos);
  EXPECT_NE(error_of([&] { read_checkpoint(dir / "absent.h5"); }).find("no such file"),
            std::string::npos);
  EXPECT_THROW(find_latest_checkpoint(dir.path()), std::runtime_error);  // neither slot exists
  // Python raises io/'s errors as OSError: they must all be IoError, damaged content included.
  EXPECT_THROW(read_checkpoint(dir / "garbage.h5"), IoError);
  EXPECT_THROW(read_checkpoint(dir / "run.h5"), IoError);
  EXPECT_THROW(read_checkpoint(dir / "absent.h5"), IoError);
  EXPECT_THROW(find_latest_checkpoint(dir.path()), IoError);
}

TEST(Checkpoint, NewerFormatAndInconsistentShapesAreRejected) {
  TempDir dir;
  const auto path = dir / "checkpoint.h5";
  write_checkpoint(path, sample_state(1));
  {
    h5::File f = h5::File::open(path, h5::File::Mode::read_write);
    f.set_attribute("format_version", kCheckpointFormatVersion + 1);
  }
  EXPECT_NE(error_of([&] { read_checkpoint(path); })
                .find(fmt::format("format version {} is not supported", kCheckpointFormatVersion + 1)),
            std::string::npos);

  write_checkpoint(path, sample_state(1));
  {
    h5::File f = h5::File::open(path, h5::File::Mode::read_write);
    f.write_matrix("reference_positions", Points::Zero(5, 3));  // N = 6 elsewhere
  }
  EXPECT_NE(error_of([&] {
              read_checkpoint(path);
            }).find("reference_positions has 5 rows, positions has 6"),
            std::string::npos);

  write_checkpoint(path, sample_state(1));
  {
    h5::File f = h5::File::open(path, h5::File::Mode::read_write);
    h5::RowMatrixXd x = f.read_matrix<double>("positions");
    x(2, 1) = std::nan("");
    f.write_matrix("positions", x);
    f.remove("extra");
  }
  const std::string msg = error_of([&] { read_checkpoint(path); });
  EXPECT_EQ(msg.rfind("checkpoint '" + path.string() + "': ", 0), 0u) << msg;
  EXPECT_NE(msg.find("extra"), std::string::npos) << msg;  // the missing dataset is named
}

TEST(Checkpoint, ChangedNumbersAreDetectedByTheChecksum) {
  TempDir dir;
  const auto path = dir / "checkpoint.h5";
  write_checkpoint(path, sample_state(1));
  {
    h5::File f = h5::File::open(path, h5::File::Mode::read_write);
    Eigen::VectorXd w = f.read_vector<double>("wall_state");
    w(5) = std::nextafter(w(5), 2.0);  // one ulp: still finite and well-shaped
    f.write_vector("wall_state", w);
  }
  const std::string msg = error_of([&] { read_checkpoint(path); });
  EXPECT_NE(msg.find("checksum mismatch"), std::string::npos) << msg;
}

TEST(Checkpoint, NonFiniteStateIsNotWrittenAndKeepsTheLastGoodOne) {
  TempDir dir;
  const auto path = dir / "checkpoint.h5";
  write_checkpoint(path, sample_state(1));
  CheckpointState bad = sample_state(2);
  bad.positions(3, 0) = INFINITY;
  EXPECT_NE(
      error_of([&] { write_checkpoint(path, bad); }).find("positions contain NaN or infinity"),
      std::string::npos);
  bad = sample_state(2);
  bad.triangles(0, 0) = 6;  // N = 6: out of range
  EXPECT_THROW(write_checkpoint(path, bad), std::runtime_error);
  EXPECT_EQ(read_checkpoint(path).t, sample_state(1).t);  // untouched
  EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"checkpoint.h5"});
}

TEST(Checkpoint, RunIdRoundTripsAndOldFilesWithoutOneStillRead) {
  TempDir dir;
  CheckpointState s = sample_state(1);
  s.run_id = "0123456789abcdef0123456789abcdef";
  write_checkpoint(dir / "checkpoint.h5", s);
  EXPECT_EQ(read_checkpoint(dir / "checkpoint.h5").run_id, s.run_id);
  // A file from before run ids: no attribute, and the checksum does not include it.
  s.run_id.clear();
  write_checkpoint(dir / "old.h5", s);
  {
    h5::File f = h5::File::open(dir / "old.h5");
    EXPECT_FALSE(f.has_attribute("run_id"));
    EXPECT_TRUE(f.has_attribute("mesh_hash"));
  }
  EXPECT_EQ(read_checkpoint(dir / "old.h5").run_id, "");
}

TEST(Checkpoint, AStateBeforeTheFirstStepHasDtZero) {
  // An interrupt before the first step writes dt = 0; it was refused ("dt = 0 is not positive"),
  // so the interrupted run ended with an error and no checkpoint.
  TempDir dir;
  CheckpointState s = sample_state(1);
  s.dt = 0;
  write_checkpoint(dir / "checkpoint.h5", s);
  EXPECT_EQ(read_checkpoint(dir / "checkpoint.h5").dt, 0.0);
  s.dt = -1e-3;
  EXPECT_NE(error_of([&] { write_checkpoint(dir / "checkpoint.h5", s); }).find("dt = -0.001 is negative"), std::string::npos);
}

TEST(Checkpoint, ADamagedWriteIsNeverRenamedIntoPlace) {
  // A full disk produced checkpoints that closed without an error but held zeroed data; they
  // were renamed over the last good file. Simulate it: damage the temporary between the write
  // and the rename. The damage is one changed number (the checksum catches it) and, second,
  // a zeroed tail (HDF5 cannot read it).
  TempDir dir;
  const auto path = dir / "checkpoint.h5";
  write_checkpoint(path, sample_state(1));
  write_checkpoint(path, sample_state(2));
  const std::vector<std::function<void(const std::filesystem::path&)>> damages = {
      [](const std::filesystem::path& tmp) {
        h5::File f = h5::File::open(tmp, h5::File::Mode::read_write);
        h5::RowMatrixXd x = f.read_matrix<double>("positions");
        x(0, 0) = 0;
        f.write_matrix("positions", x);
        f.close();
      },
      [](const std::filesystem::path& tmp) {
        const auto n = std::filesystem::file_size(tmp);
        std::filesystem::resize_file(tmp, n / 2);
        std::filesystem::resize_file(tmp, n);  // same size, second half zeros
      }};
  for (const auto& damage : damages) {
    set_checkpoint_write_hook_for_tests(damage);
    const std::string msg = error_of([&] { write_checkpoint(path, sample_state(3)); });
    set_checkpoint_write_hook_for_tests(nullptr);
    EXPECT_EQ(msg.rfind("checkpoint '" + path.string() + "': the file just written", 0), 0u) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    // Both slots untouched, no temporary left.
    EXPECT_EQ(read_checkpoint(path).t, sample_state(2).t);
    EXPECT_EQ(read_checkpoint(dir / "checkpoint.prev.h5").t, sample_state(1).t);
    EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"checkpoint.h5", "checkpoint.prev.h5"}));
  }
}

TEST(Checkpoint, ADamagedNewestFileDoesNotPushOutThePreviousOne) {
  TempDir dir;
  const auto path = dir / "checkpoint.h5";
  write_checkpoint(path, sample_state(1));
  write_checkpoint(path, sample_state(2));
  testing::write_text(path, std::string(4096, 'x'));  // the newest is garbage
  write_checkpoint(path, sample_state(3));
  EXPECT_EQ(read_checkpoint(path).t, sample_state(3).t);
  EXPECT_EQ(read_checkpoint(dir / "checkpoint.prev.h5").t, sample_state(1).t);  // still the good one
}

TEST(Checkpoint, RestartFallsBackToThePreviousSlotAndSaysWhy) {
  TempDir dir;
  const auto path = dir / "checkpoint.h5";
  write_checkpoint(path, sample_state(1));
  write_checkpoint(path, sample_state(2));
  {
    h5::File f = h5::File::open(path, h5::File::Mode::read_write);
    f.write_string("scene_toml", "");  // what the full disk left: empty strings
  }
  const LoadedCheckpoint l = load_checkpoint_for_restart(path);
  EXPECT_EQ(l.path, dir / "checkpoint.prev.h5");
  EXPECT_EQ(l.state.t, sample_state(1).t);
  EXPECT_NE(l.fallback_reason.find("checksum mismatch"), std::string::npos) << l.fallback_reason;
  // A folder means its checkpoint.h5 (with the same fallback).
  EXPECT_EQ(load_checkpoint_for_restart(dir.path()).path, dir / "checkpoint.prev.h5");
  // An explicit previous slot, or both damaged: an error naming both problems.
  testing::write_text(dir / "checkpoint.prev.h5", "garbage");
  const std::string msg = error_of([&] { load_checkpoint_for_restart(path); });
  EXPECT_NE(msg.find("checksum mismatch"), std::string::npos) << msg;
  EXPECT_NE(msg.find("the previous one is not usable either"), std::string::npos) << msg;
}

TEST(Checkpoint, AFolderIsNamedAsSuchNotWithRawHdf5Text) {
  TempDir dir;
  std::filesystem::create_directory(dir / "run");
  const std::string msg = error_of([&] { read_checkpoint(dir / "run"); });
  EXPECT_NE(msg.find("is a folder, not a checkpoint file"), std::string::npos) << msg;
  EXPECT_EQ(msg.find("errno"), std::string::npos) << msg;  // once: "... errno = 21, error message = 'Is a directory', buf = 0x..."
  const std::string viaRestart = error_of([&] { load_checkpoint_for_restart(dir / "run"); });
  EXPECT_NE(viaRestart.find("checkpoint.h5': no such file"), std::string::npos) << viaRestart;
}

}  // namespace
}  // namespace capsflow::io
