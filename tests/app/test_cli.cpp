// The capsflow executable end to end: command-line errors, output-folder safety, blow-up
// handling, and restart equivalence.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "capsflow/core/io/checkpoint.hpp"

namespace fs = std::filesystem;

namespace {

struct Result {
  int code;
  std::string out, err;
};

Result run(const std::string& args, const fs::path& dir) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = std::string(CAPSFLOW_EXE) + " " + args + " > " + out.string() + " 2> " + err.string();
  const int status = std::system(cmd.c_str());
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / ("capsflow-cli-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

int count_lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

// A tiny, fast scene: 320 elements, membrane wall.
const char* kTiny = "--set mesh.level=2 --set wall.model=membrane --set wall.law=nh --set flow.ca_s=0.2 --threads 2";

}  // namespace

TEST(Cli, MissingSceneIsOneLineError) {
  TempDir d;
  const Result r = run("info " + (d.path / "nope.toml").string(), d.path);
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("nope.toml"), std::string::npos) << r.err;
}

TEST(Cli, BadKeyNamesFileLineAndKey) {
  TempDir d;
  std::ofstream(d.path / "bad.toml") << "[mesh]\nlevel = 2\nlevle = 3\n";
  const Result r = run("run " + (d.path / "bad.toml").string() + " -o " + (d.path / "out").string(), d.path);
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("bad.toml:3: mesh.levle: unknown key"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d.path / "out"));  // nothing created before the scene is valid
}

TEST(Cli, ExistingOutputIsRefusedAndLeftUntouched) {
  TempDir d;
  const fs::path out = d.path / "out";
  fs::create_directories(out);
  std::ofstream(out / "summary.json") << "precious";
  const Result r = run(std::string("run ") + kTiny + " --set time.t_end=0.01 -o " + out.string(), d.path);
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
  std::ifstream in(out / "summary.json");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "precious");
  EXPECT_EQ(std::distance(fs::directory_iterator(out), fs::directory_iterator()), 1);
}

TEST(Cli, TooLargeFixedStepStopsCleanlyAsBlowUp) {
  TempDir d;
  const fs::path out = d.path / "out";
  // dt = 0.5 is ~30× the membrane stability limit of this mesh: the run must stop by itself.
  const Result r = run(std::string("run ") + kTiny + " --set time.dt=0.5 --set time.t_end=20 -o " + out.string(), d.path);
  EXPECT_EQ(r.code, 3) << r.err;
  std::ifstream in(out / "summary.json");
  const auto s = nlohmann::json::parse(in);
  EXPECT_EQ(s["stop_reason"], "blow_up");
  EXPECT_LT(s["t"].get<double>(), 20.0);
  EXPECT_TRUE(std::isfinite(s["D13"].get<double>()));
  EXPECT_TRUE(fs::exists(out / "run.xmf"));
  EXPECT_NO_THROW(capsflow::io::read_checkpoint(out / "checkpoint.h5"));  // a valid, finite checkpoint
}

TEST(Cli, RestartMatchesUninterruptedRun) {
  TempDir d;
  const std::string base = std::string("run ") + kTiny + " --set output.every=0.05 --set output.checkpoint_every=0.1";
  const Result a = run(base + " --set time.t_end=0.3 -o " + (d.path / "a").string(), d.path);
  ASSERT_EQ(a.code, 0) << a.err;
  const Result b1 = run(base + " --set time.t_end=0.15 -o " + (d.path / "b").string(), d.path);
  ASSERT_EQ(b1.code, 0) << b1.err;
  const Result b2 = run("run --threads 2 --restart " + (d.path / "b" / "checkpoint.h5").string() + " --set time.t_end=0.3", d.path);
  ASSERT_EQ(b2.code, 0) << b2.err;
  const auto ca = capsflow::io::read_checkpoint(d.path / "a" / "checkpoint.h5");
  const auto cb = capsflow::io::read_checkpoint(d.path / "b" / "checkpoint.h5");
  EXPECT_EQ(ca.step, cb.step);
  EXPECT_DOUBLE_EQ(ca.t, 0.3);
  EXPECT_DOUBLE_EQ(cb.t, 0.3);
  // Same thread count, same operations in the same order: identical to round-off (in practice
  // bit for bit; 1e-13 allows a different summation order in a library).
  EXPECT_LT((ca.positions - cb.positions).cwiseAbs().maxCoeff(), 1e-13);
  // The restarted folder holds one continuous series: 7 output rows (t = 0, 0.05, ..., 0.3).
  std::ifstream csv(d.path / "b" / "timeseries.csv");
  const std::string text(std::istreambuf_iterator<char>(csv), {});
  EXPECT_EQ(count_lines(text), 1 + 7) << text;
}

TEST(Cli, VersionPrintsGitAndDependencies) {
  TempDir d;
  const Result r = run("--version", d.path);
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("\"eigen\""), std::string::npos);
  EXPECT_NE(r.out.find("\"hdf5\""), std::string::npos);
  EXPECT_NE(r.out.find("git"), std::string::npos);
}
