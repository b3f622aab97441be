// The capsflow executable end to end: command-line errors, output-folder safety, blow-up
// handling, and restart equivalence.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <map>
#include <regex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <thread>

#include "capsflow/core/io/checkpoint.hpp"
#include "capsflow/core/io/h5.hpp"
#include "capsflow/core/io/output_folder.hpp"

namespace fs = std::filesystem;

namespace {

struct Result {
  int code;
  std::string out, err;
};

// `capsflow ARGS`, or with with_exe = false the whole command line ARGS (e.g. under timeout).
Result run(const std::string& args, const fs::path& dir, bool with_exe = true) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = (with_exe ? std::string(CAPSFLOW_EXE) + " " : std::string()) + args + " > " + out.string() + " 2> " + err.string();
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

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Every file of a folder with its bytes: to show that a refused command changed nothing.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) files[e.path().filename().string()] = slurp(e.path());
  return files;
}

nlohmann::json summary_of(const fs::path& dir) { return nlohmann::json::parse(slurp(dir / "summary.json")); }

// The t column of timeseries.csv.
std::vector<double> csv_times(const fs::path& dir) {
  std::ifstream in(dir / "timeseries.csv");
  std::vector<double> t;
  std::string line;
  std::getline(in, line);  // header; t is the first column
  while (std::getline(in, line)) t.push_back(std::stod(line.substr(0, line.find(','))));
  return t;
}

// capsflow started in the background with the environment of a user's shell (no
// OMP_WAIT_POLICY, no CAPSFLOW_NO_REEXEC: it re-executes itself once).
pid_t spawn(const std::string& args, const fs::path& dir) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::unsetenv("OMP_WAIT_POLICY");
    ::unsetenv("CAPSFLOW_NO_REEXEC");
    const std::string cmd = "exec " + std::string(CAPSFLOW_EXE) + " " + args + " > " + (dir / "stdout.txt").string() +
                            " 2> " + (dir / "stderr.txt").string();
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

// Waits up to `seconds` for `pid`; returns its exit code, or -1 after killing it (a hang).
int wait_or_kill(pid_t pid, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int status = 0;
  while (std::chrono::steady_clock::now() < end) {
    if (::waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &status, 0);
  return -1;
}

bool wait_for_file(const fs::path& p, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (fs::exists(p)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

// The start-up line of a restart: "output: DIR (restart from t = T)", T as {:g}.
std::string fmt_restart_from(double t) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "(restart from t = %g)", t);
  return buf;
}

// A run that may hang on the old code is bounded: timeout(1) ends it after 120 s (exit 124).
const char* kBounded = "timeout -k 10 120 ";

// A tiny, fast scene: 320 elements, membrane wall.
const char* kTiny = "--set mesh.level=2 --set wall.model=membrane --set wall.law=nh --set flow.ca_s=0.2 --threads 2";

}  // namespace

TEST(Cli, SetBeforeTheSceneFileLeavesTheSceneFileAScene) {
  TempDir d;
  // `--set` takes one value: the scene file after it is the scene, not a second override.
  const Result r = run("info --set mesh.level=1 " + (d.path / "nope.toml").string(), d.path);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("nope.toml"), std::string::npos) << r.err;  // read as the scene (and missing)
  const Result ok = run("info --set mesh.level=1 --set time.t_end=0.5 " + std::string(CAPSFLOW_SOURCE_DIR) + "/scenes/quick.toml", d.path);
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.out.find("quick.toml"), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("t_end = 0.5"), std::string::npos) << ok.out;
}

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
  // dt = 0.5 is ~30× Heun's membrane stability limit of this mesh: the run must stop by itself.
  const Result r =
      run(std::string("run ") + kTiny + " --set time.scheme=heun --set time.dt=0.5 --set time.t_end=20 -o " + out.string(), d.path);
  EXPECT_EQ(r.code, 3) << r.err;
  std::ifstream in(out / "summary.json");
  const auto s = nlohmann::json::parse(in);
  EXPECT_EQ(s["stop_reason"], "blow_up");
  EXPECT_LT(s["t"].get<double>(), 20.0);
  EXPECT_TRUE(std::isfinite(s["D13"].get<double>()));
  EXPECT_TRUE(fs::exists(out / "run.xmf"));
  EXPECT_NO_THROW(capsflow::io::read_checkpoint(out / "checkpoint.h5"));  // a valid, finite checkpoint
}

// Both schemes. Heun lands on every output time, so any of them is a point the uninterrupted run
// passes too; RKC (the default) lands on checkpoint times and t_end only, so there the
// interruption is at a checkpoint time — and resumes from a periodic checkpoint, which must name
// the next checkpoint after its own time, or a restart has no time to step.
TEST(Cli, RestartMatchesUninterruptedRun) {
  for (const auto& [scheme, t_stop] : {std::pair<std::string, std::string>{"heun", "0.15"}, {"rkc", "0.2"}}) {
    SCOPED_TRACE(scheme);
    TempDir d;
    const std::string base = std::string("run ") + kTiny + " --set time.scheme=" + scheme +
                             " --set output.every=0.05 --set output.checkpoint_every=0.1";
    const Result a = run(base + " --set time.t_end=0.3 -o " + (d.path / "a").string(), d.path);
    ASSERT_EQ(a.code, 0) << a.err;
    const Result b1 = run(base + " --set time.t_end=" + t_stop + " -o " + (d.path / "b").string(), d.path);
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
    // A run killed between checkpoints continues from its last periodic one, in its folder: a run
    // to 0.35 keeps the periodic checkpoint of 0.3 as checkpoint.prev.h5 beside the final one.
    const fs::path c = d.path / "c";
    ASSERT_EQ(run(base + " --set time.t_end=0.35 -o " + c.string(), d.path).code, 0);
    const auto whole = capsflow::io::read_checkpoint(c / "checkpoint.h5");
    fs::remove(c / "summary.json");
    fs::rename(c / "checkpoint.prev.h5", c / "checkpoint.h5");
    ASSERT_DOUBLE_EQ(capsflow::io::read_checkpoint(c / "checkpoint.h5").t, 0.3);
    const Result c2 = run("run --threads 2 --restart " + (c / "checkpoint.h5").string(), d.path);
    ASSERT_EQ(c2.code, 0) << c2.err;
    const auto resumed = capsflow::io::read_checkpoint(c / "checkpoint.h5");
    EXPECT_DOUBLE_EQ(resumed.t, 0.35);
    EXPECT_EQ(resumed.step, whole.step);
    EXPECT_LT((resumed.positions - whole.positions).cwiseAbs().maxCoeff(), 1e-13);  // as above
  }
}

TEST(Cli, VersionPrintsGitAndDependencies) {
  TempDir d;
  const Result r = run("--version", d.path);
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("\"eigen\""), std::string::npos);
  EXPECT_NE(r.out.find("\"hdf5\""), std::string::npos);
  EXPECT_NE(r.out.find("git"), std::string::npos);
}

// ---- data safety and input hardening ----

TEST(Cli, RestartRefusesAFolderOfAnotherRunAndLeavesItUntouched) {
  // Item 1. `--restart A/checkpoint.h5 -o B` with B another, finished run: B's later steps were
  // deleted, timeseries.csv cut, checkpoint and summary replaced by A's, with exit 0.
  TempDir d;
  const fs::path a = d.path / "a", b = d.path / "b";
  ASSERT_EQ(run(std::string("run ") + kTiny + " --set time.t_end=0.1 -o " + a.string(), d.path).code, 0);
  ASSERT_EQ(run(std::string("run ") + kTiny + " --set time.t_end=0.2 -o " + b.string(), d.path).code, 0);
  const auto before = snapshot(b);
  const Result r = run("run --threads 2 --restart " + (a / "checkpoint.h5").string() + " --set time.t_end=0.3 -o " + b.string(), d.path);
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("belongs to another run"), std::string::npos) << r.err;
  EXPECT_EQ(snapshot(b), before);  // every file byte for byte
  // The run id is in run.h5, the checkpoint and the summary alike.
  const std::string id = summary_of(a).at("run_id");
  EXPECT_EQ(id.size(), 32u);
  EXPECT_EQ(capsflow::io::read_checkpoint(a / "checkpoint.h5").run_id, id);
  EXPECT_EQ(capsflow::io::h5::File::open(a / "run.h5").read_string("metadata/run_id"), id);
  EXPECT_NE(summary_of(b).at("run_id"), id);
  EXPECT_EQ(summary_of(a).at("mesh_hash"), summary_of(b).at("mesh_hash"));  // same mesh, yet another run
}

TEST(Cli, RestartIntoANewFolderStartsThereAndReferencesTheHistory) {
  // Items 1 and 5: `--restart` could not write into a new or empty folder.
  TempDir d;
  const fs::path a = d.path / "a", c = d.path / "c", e = d.path / "empty";
  ASSERT_EQ(run(std::string("run ") + kTiny + " --set time.t_end=0.2 -o " + a.string(), d.path).code, 0);
  const auto before = snapshot(a);
  const Result r = run("run --threads 2 --restart " + (a / "checkpoint.h5").string() + " --set time.t_end=0.3 -o " + c.string(), d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(snapshot(a), before);  // the parent run is only read
  // History referenced, not copied: C's series start at the checkpoint time.
  EXPECT_EQ(csv_times(c), (std::vector<double>{0.2, 0.3}));  // exact: the last step lands on t_end
  const auto f = capsflow::io::h5::File::open(c / "run.h5");
  EXPECT_EQ(f.read_string("metadata/parent_run_id"), summary_of(a).at("run_id").get<std::string>());
  EXPECT_EQ(f.read_string("metadata/parent_checkpoint"), fs::absolute(a / "checkpoint.h5").lexically_normal().string());
  EXPECT_EQ(f.open_group("metadata").attribute_double("t_start"), 0.2);
  EXPECT_NE(summary_of(c).at("run_id"), summary_of(a).at("run_id"));
  EXPECT_EQ(summary_of(c).at("steps"), capsflow::io::read_checkpoint(c / "checkpoint.h5").step);
  // An existing empty folder, and --restart given a folder (its checkpoint.h5).
  fs::create_directories(e);
  const Result re = run("run --threads 2 --restart " + a.string() + " --set time.t_end=0.3 -o " + e.string(), d.path);
  EXPECT_EQ(re.code, 0) << re.err;
  EXPECT_EQ(csv_times(e), csv_times(c));
}

TEST(Cli, RestartOverridesAreAppliedOrRefused) {
  // Item 5: mesh keys were ignored but recorded, wall.model switched silently, and a changed
  // output.every reused the old output index (3·0.05 = 0.15 < t = 0.2: a negative step).
  TempDir d;
  const fs::path a = d.path / "a";
  ASSERT_EQ(run(std::string("run ") + kTiny + " --set time.t_end=0.2 -o " + a.string(), d.path).code, 0);
  const auto before = snapshot(a);
  const std::string restart = "run --threads 2 --restart " + (a / "checkpoint.h5").string() + " --set time.t_end=0.4 ";
  for (const std::string set : {"--set mesh.level=3", "--set mesh.shape=sphere", "--set wall.model=gsmb"}) {
    const Result r = run(restart + set, d.path);
    EXPECT_EQ(r.code, 1) << set;
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("capsflow: error: " + set.substr(0, set.find('=')) + ": "), std::string::npos) << r.err;
    EXPECT_EQ(snapshot(a), before) << set;
  }
  const Result r = run(restart + "--set output.every=0.05", d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<double> t = csv_times(a);
  ASSERT_EQ(t.size(), 3u + 4u) << "0, 0.1, 0.2, then every 0.05 to 0.4";
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(t[3 + k], 0.25 + 0.05 * k, 1e-12);  // k·0.05 in doubles: within 1 ulp
  EXPECT_EQ(summary_of(a).at("scene").at("output").at("every"), 0.05);
}

TEST(Cli, EveryFileWrittenIsInTheManifestAndOverwriteKeepsTheRest) {
  // Item 2: --overwrite removed `log`, `capsflow.log` and any checkpoint*.h5, including the log
  // of this very command (`> out/log`).
  TempDir d;
  const fs::path out = d.path / "out";
  ASSERT_EQ(run(std::string("run ") + kTiny + " --set time.t_end=0.2 --set output.checkpoint_every=0.05 -o " + out.string(), d.path).code, 0);
  ASSERT_EQ(run("run --threads 2 --restart " + out.string() + " --set time.t_end=0.3", d.path).code, 0);
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_TRUE(capsflow::io::is_capsflow_output_name(e.path().filename().string())) << e.path();
  std::ofstream(out / "capsflow.log") << "earlier log";
  std::ofstream(out / "checkpoint_backup_from_cluster.h5") << "precious";
  const std::string cmd = std::string(CAPSFLOW_EXE) + " run " + kTiny + " --set time.t_end=0.1 --overwrite -o " + out.string() +
                          " > " + (out / "log").string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_NE(slurp(out / "log").find("stopped: t_end"), std::string::npos);  // its own log survived
  EXPECT_EQ(slurp(out / "capsflow.log"), "earlier log");
  EXPECT_EQ(slurp(out / "checkpoint_backup_from_cluster.h5"), "precious");
  EXPECT_EQ(summary_of(out).at("t"), 0.1);
  // The earlier run's checkpoints are gone: the previous slot holds this run's first one (t = 0).
  const capsflow::io::CheckpointState prev = capsflow::io::read_checkpoint(out / "checkpoint.prev.h5");
  EXPECT_EQ(prev.t, 0.0);
  EXPECT_EQ(prev.run_id, summary_of(out).at("run_id").get<std::string>());
}

TEST(Cli, AFullDiskIsAOneLineErrorWithExitCode1NotACrash) {
  // Item 3. A file-size limit (RLIMIT_FSIZE, SIGXFSZ ignored) fails writes like a full disk,
  // without privileges. capsflow printed the HDF5 error, then crashed in HDF5's exit handler
  // (exit 139). Limits of 20 kB and 50 kB break run.h5 at different steps.
  TempDir d;
  for (const int blocks : {40, 100}) {  // 512-byte blocks (dash's ulimit -f)
    const fs::path out = d.path / ("out" + std::to_string(blocks));
    const std::string cmd = "sh -c \"trap '' XFSZ; ulimit -f " + std::to_string(blocks) + "; exec " + CAPSFLOW_EXE + " run " + kTiny +
                            " --set time.t_end=1 --set output.every=0.01 --set output.checkpoint_every=0.02 -o " + out.string() +
                            "\" > " + (d.path / "o.txt").string() + " 2> " + (d.path / "e.txt").string();
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 1) << blocks;
    const std::string err = slurp(d.path / "e.txt");
    EXPECT_EQ(count_lines(err), 1) << err;
    EXPECT_EQ(err.rfind("capsflow: error: ", 0), 0u) << err;
    EXPECT_NE(err.find("File too large"), std::string::npos) << err;
    // 50 kB holds the first output and the checkpoint written as the run starts (each file is
    // limited on its own): the run can be continued although the limit struck before the first
    // periodic checkpoint at γ̇t = 0.02 (at 40 kB no checkpoint is left at all).
    if (blocks == 100) {
      EXPECT_TRUE(fs::exists(out / "checkpoint.h5")) << err;
    }
    // Whatever checkpoint made it to disk is complete: a damaged one is never renamed into place.
    for (const char* ck : {"checkpoint.h5", "checkpoint.prev.h5"}) {
      if (fs::exists(out / ck)) {
        EXPECT_NO_THROW(capsflow::io::read_checkpoint(out / ck)) << blocks << " " << ck;
      }
    }
  }
}

TEST(Cli, ADamagedLatestCheckpointFallsBackToThePreviousOneSayingSo) {
  // Item 3: "checksum mismatch: the file is damaged", without a word about checkpoint.prev.h5.
  TempDir d;
  const fs::path out = d.path / "out";
  ASSERT_EQ(run(std::string("run ") + kTiny + " --set time.t_end=0.2 --set output.checkpoint_every=0.1 -o " + out.string(), d.path).code, 0);
  const double t_prev = capsflow::io::read_checkpoint(out / "checkpoint.prev.h5").t;
  {
    capsflow::io::h5::File f = capsflow::io::h5::File::open(out / "checkpoint.h5", capsflow::io::h5::File::Mode::read_write);
    f.write_string("scene_toml", "");  // what a full disk left behind
    f.close();
  }
  const Result r = run("run --threads 2 --restart " + (out / "checkpoint.h5").string() + " --set time.t_end=0.3", d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("checksum mismatch"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("continuing from the previous checkpoint " + (out / "checkpoint.prev.h5").string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(fmt_restart_from(t_prev)), std::string::npos) << r.out;
  EXPECT_EQ(summary_of(out).at("t"), 0.3);
}

TEST(Cli, SigintStopsARunWithAHugeTEndAndTheProcessIsNamedCapsflow) {
  // Item 4: t_end = 1e308 looped for ever after one step (the checkpoint-index loop, with
  // 1e-12·t_end = 1e296 as "tolerance") and ignored SIGINT. Item 7: the re-execution through
  // /proc/self/exe named the process "exe" in ps.
  TempDir d;
  const fs::path out = d.path / "out";
  // Outputs and checkpoints every 1e302: 1e6 of each, within the counts a scene may ask for.
  const pid_t pid = spawn(std::string("run ") + kTiny +
                              " --set time.t_end=1e308 --set output.every=1e302 --set output.checkpoint_every=1e302 -o " +
                              out.string(),
                          d.path);
  ASSERT_TRUE(wait_for_file(out / "run.xmf", 60)) << slurp(d.path / "stderr.txt");  // first output: handlers installed
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // some steps into the loop
  std::string comm = slurp("/proc/" + std::to_string(pid) + "/comm");
  EXPECT_EQ(comm, "capsflow\n");
  ::kill(pid, SIGINT);
  EXPECT_EQ(wait_or_kill(pid, 60), 130) << slurp(d.path / "stderr.txt");  // a prompt stop, not a hang
  const auto s = summary_of(out);
  EXPECT_EQ(s.at("stop_reason"), "interrupted");
  EXPECT_LT(s.at("t").get<double>(), 100.0);  // times were not snapped to output times by a 1e296 tolerance
  EXPECT_NO_THROW(capsflow::io::read_checkpoint(out / "checkpoint.h5"));
}

TEST(Cli, AStepWithoutProgressStopsWithANamedReason) {
  // Item 4: gradient entries of 1e300 give |L| = inf, a flow-capped dt = 0 and a loop without
  // progress whose interrupt then failed to checkpoint (dt = 0 was refused).
  TempDir d;
  const fs::path out = d.path / "out";
  const Result r = run(std::string(kBounded) + CAPSFLOW_EXE + " run " + kTiny +
                           " --set flow.type=linear --set 'flow.gradient=[[1e300,0,0],[0,0,0],[0,0,-1e300]]' -o " + out.string(),
                       d.path, false);
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_NE(r.out.find("no progress at step 1"), std::string::npos) << r.out;
  EXPECT_EQ(summary_of(out).at("stop_reason"), "no_progress");
  EXPECT_NO_THROW(capsflow::io::read_checkpoint(out / "checkpoint.h5"));
}

TEST(Cli, CommandLineMessages) {
  TempDir d;
  // Item 7: --threads -1 printed the range "0.000000 to 179769313486231570814527423731704356798070...".
  const Result t = run("run --threads -1", d.path);
  EXPECT_EQ(t.code, 2);  // command-line errors: exit code 2
  EXPECT_NE(t.err.find("--threads: Value -1 not in range 0 to 4096"), std::string::npos) << t.err;
  EXPECT_EQ(t.err.find("17976931348623157"), std::string::npos) << t.err;
  // --restart DIR without a checkpoint: once two lines of raw HDF5 text ("errno = 21, ... buf = 0x...").
  fs::create_directories(d.path / "empty");
  const Result r = run("run --restart " + (d.path / "empty").string(), d.path);
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("checkpoint.h5': no such file"), std::string::npos) << r.err;
  // A checkpoint given as the scene.
  ASSERT_EQ(run(std::string("run ") + kTiny + " --set time.t_end=0.05 -o " + (d.path / "a").string(), d.path).code, 0);
  const Result s = run("info " + (d.path / "a" / "checkpoint.h5").string(), d.path);
  EXPECT_EQ(s.code, 1);
  EXPECT_NE(s.err.find("is an HDF5 file (a checkpoint?), not a TOML scene; to continue a run use: capsflow run --restart"),
            std::string::npos) << s.err;
}

TEST(Cli, InfoCountsTheStepsOutputTimesForceAndNotesTheCapillaryNumber) {
  TempDir d;
  // Item 7: `info` said "about 2 steps" (t_end/dt) where outputs every 1e-4 force one step each.
  const Result r = run("info --set mesh.level=1 --set time.scheme=heun --set time.t_end=0.01 --set output.every=0.0001", d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("about 100 steps to t_end = 0.01"), std::string::npos) << r.out;
  // Item 7: the default scene gives ca_v, so a thicker wall silently meant a smaller Ca_s.
  const Result n = run("info --set mesh.level=1 --set wall.thickness=0.06", d.path);
  EXPECT_NE(n.out.find("# note: Ca_s = 0.05 follows from flow.ca_v = 0.003 and wall.thickness = 0.06"), std::string::npos) << n.out;
  const Result g = run("run --set mesh.level=1 --set wall.thickness=0.06 --set time.t_end=0.01 --threads 2 -o " + (d.path / "o").string(), d.path);
  ASSERT_EQ(g.code, 0) << g.err;
  EXPECT_NE(g.out.find("note: Ca_s = 0.05 follows from flow.ca_v"), std::string::npos) << g.out;
}

// The timing table gives every phase in CPU seconds beside its wall seconds (how parallel it is).
TEST(Cli, TheTimingTableHasTheCpuSecondsOfEveryPhase) {
  TempDir d;
  ASSERT_EQ(run(std::string("run ") + kTiny + " --set time.t_end=0.05 -o " + (d.path / "o").string(), d.path).code, 0);
  const nlohmann::json timing = summary_of(d.path / "o").at("timing");
  double sum = 0;
  for (const auto& [phase, wall] : timing.at("phases").items()) {
    ASSERT_TRUE(timing.at("cpu_seconds").contains(phase)) << phase;
    EXPECT_GE(timing["cpu_seconds"][phase].get<double>(), 0.0) << phase;
    sum += timing["cpu_seconds"][phase].get<double>();
  }
  EXPECT_EQ(timing["cpu_seconds"].size(), timing["phases"].size());
  // "other" is the rest of the segment's CPU time, so the phases add up to it (round-off only).
  EXPECT_NEAR(sum, timing.at("total_cpu_seconds").get<double>(), 1e-9 * sum + 1e-12);
  EXPECT_EQ(timing.at("threads"), 2);  // kTiny's --threads 2
}

// `info` predicted 2 evaluations per Heun step (110 here) where the run made 139: every
// output evaluates the velocity once more, and ρ is refreshed by power iteration every 50 steps.
TEST(Cli, InfoPredictsTheEvaluationsOfAHeunRun) {
  TempDir d;
  const std::string scene =
      "--set mesh.level=2 --set wall.model=membrane --set wall.law=nh --set flow.ca_s=0.2 --set time.t_end=0.5 --set time.scheme=heun";
  const Result i = run("info " + scene, d.path);
  ASSERT_EQ(i.code, 0) << i.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(i.out, m, std::regex("steps to t_end = 0.5: ([0-9]+) evaluations"))) << i.out;
  const double predicted = std::stod(m[1]);
  ASSERT_EQ(run("run " + scene + " --threads 1 -o " + (d.path / "o").string(), d.path).code, 0);
  const double made = summary_of(d.path / "o").at("rhs_evaluations").get<double>();
  // 10 %: Heun's step is recomputed from the deforming shape at every step, which info cannot
  // know; the old count (2 per step) was 21 % low on this case.
  EXPECT_NEAR(predicted, made, 0.10 * made) << i.out;
}

// A forced fluid.fmm_order with the direct back end was silently ignored; `info` and the
// run now warn (docs §2.6).
TEST(Cli, AForcedFmmOrderThatTheDirectSumIgnoresIsWarnedAbout) {
  TempDir d;
  const std::string set = "--set mesh.level=1 --set fluid.backend=direct --set fluid.fmm_order=8";
  const Result i = run("info " + set, d.path);
  ASSERT_EQ(i.code, 0) << i.err;
  EXPECT_NE(i.out.find("warning         fluid.fmm_order = 8 is not used"), std::string::npos) << i.out;
  const Result r = run(std::string("run ") + kTiny + " " + set + " --set time.t_end=0.01 -o " + (d.path / "o").string(), d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE((r.out + r.err).find("fluid.fmm_order = 8 is not used"), std::string::npos) << r.out << r.err;
}

// The step and output counts are bounded before anything runs: by `info`, and on a
// restart for what --set changes (the scene of a restart is checked like any other).
TEST(Cli, CountsBeyondTheBoundAreRefusedByInfoAndOnARestart) {
  TempDir d;
  const Result i = run("info --set output.every=1e-300", d.path);
  EXPECT_EQ(i.code, 1);
  EXPECT_EQ(count_lines(i.err), 1) << i.err;
  EXPECT_NE(i.err.find("--set output.every: 1e-300 would need 2e300 outputs to time.t_end = 2"), std::string::npos) << i.err;
  const fs::path out = d.path / "o";
  ASSERT_EQ(run(std::string("run ") + kTiny + " --set time.t_end=0.02 -o " + out.string(), d.path).code, 0);
  const auto before = snapshot(out);
  const Result r = run("run --restart " + out.string() + " --set time.t_end=0.04 --set time.dt=1e-300", d.path);
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--set time.dt: 1e-300 would need 4e298 steps to time.t_end = 0.04; at most 1e9 are allowed"),
            std::string::npos) << r.err;
  EXPECT_EQ(snapshot(out), before);  // refused before anything is written
}

TEST(Cli, AThreadCountTheMachineCannotTakeIsRefusedBeforeAnyFolderIsLocked) {
  // libgomp cannot report a thread it fails to start: it prints "Thread creation failed" and
  // calls exit(1), after the run had locked its folder. Under a 4 GB address-space limit, 4096
  // threads (8 MB stacks: 32 GB) did exactly that.
  TempDir d;
  const fs::path out = d.path / "out";
  const std::string scene = " --set mesh.level=1 --set wall.model=membrane --set time.t_end=0.02 -o " + out.string();
  const std::string limited = "sh -c 'ulimit -v 4000000; exec " + std::string(CAPSFLOW_EXE) + " ";
  for (const std::string command : {"run", "study --levels 1"}) {
    const Result r = run(limited + command + " --threads 4096" + scene + "'", d.path, false);
    EXPECT_EQ(r.code, 1) << command << ": " << r.out << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << command << ": " << r.err;
    // The bound: 4 × the hardware threads (driver/thread_count.hpp), whatever this machine has.
    EXPECT_NE(r.err.find("capsflow: error: --threads 4096: more than 4 × the "), std::string::npos) << command << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << command << ": refused before the folder was created and locked";
  }
  // Within that bound on any machine (3 ≤ 4 × 1), but with thread stacks of 2 GB (`ulimit -s`, the
  // default stack of a new thread) under the same limit, at most one more thread fits: the check
  // starts the threads first and finds that.
  const Result r = run("sh -c 'ulimit -v 4000000; ulimit -s 2000000; exec " + std::string(CAPSFLOW_EXE) + " run --threads 3" +
                           scene + "'",
                       d.path, false);
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("capsflow: error: --threads 3: only "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" of 3 threads could be started here"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, ARestartFromAFifoIsRefusedInsteadOfWaitingForAWriter) {
  // HDF5 opened a FIFO given as the checkpoint and waited for ever for a writer; meshes and scenes
  // were already refused unless regular files. timeout(1) bounds the old behaviour (exit 124).
  TempDir d;
  const fs::path fifo = d.path / "ck.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string bounded = std::string("timeout -k 5 30 ") + CAPSFLOW_EXE;
  const Result r = run(bounded + " run --restart " + fifo.string() + " --threads 1", d.path, false);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("checkpoint '" + fifo.string() + "': is a FIFO, not a regular file"), std::string::npos) << r.err;
  // The same as a folder's checkpoint.h5 (--restart DIR).
  const fs::path dir = d.path / "run";
  fs::create_directories(dir);
  ASSERT_EQ(::mkfifo((dir / "checkpoint.h5").c_str(), 0600), 0);
  const Result f = run(bounded + " run --restart " + dir.string() + " --threads 1", d.path, false);
  EXPECT_EQ(f.code, 1) << f.err;
  EXPECT_NE(f.err.find("checkpoint.h5': is a FIFO, not a regular file"), std::string::npos) << f.err;
}

TEST(Cli, ASignalDuringTheSetUpStopsTheRunAsInterruptedAndWritesNothingHalfway) {
  // The handlers were installed only after the set-up. A SIGINT during it ended the process by
  // its default action, halfway through the folder; and when the parent had SIGINT ignored (a
  // background job of a script: `capsflow run … &`), it was lost and the run went on to t_end.
  // Here the parent ignores SIGINT, as such a shell does, and the signal comes as soon as the run
  // has locked its folder: early in its set-up (after the mesh; the right-hand side and the first
  // evaluation are still ahead).
  TempDir d;
  const fs::path out = d.path / "out";
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::signal(SIGINT, SIG_IGN);
    const std::string cmd = "exec " + std::string(CAPSFLOW_EXE) + " run --set mesh.level=3 --set time.t_end=0.02 --threads 1 -o " +
                            out.string() + " > " + (d.path / "stdout.txt").string() + " 2> " + (d.path / "stderr.txt").string();
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  bool locked = false;
  for (int i = 0; i < 12000 && !locked; ++i) {  // 60 s
    locked = fs::exists(out / ".capsflow.lock");
    if (!locked) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ::kill(pid, SIGINT);
  ASSERT_TRUE(locked) << slurp(d.path / "stderr.txt");
  const int code = wait_or_kill(pid, 120);
  const std::string log = slurp(d.path / "stdout.txt") + slurp(d.path / "stderr.txt");
  EXPECT_EQ(code, 130) << log;  // 0: the signal was lost and the run went on to t_end
  if (!fs::exists(out / "summary.json")) {
    // Stopped during the set-up, before the first state: nothing of the run is left.
    EXPECT_NE(log.find("signal 2 received during the set-up: stopped before the first step"), std::string::npos) << log;
    EXPECT_TRUE(!fs::exists(out) || fs::is_empty(out)) << "a folder the run created is removed again";
  } else {
    // The signal came after the first state was written (a loaded machine): the usual stop.
    EXPECT_EQ(summary_of(out).at("stop_reason"), "interrupted");
    EXPECT_EQ(summary_of(out).at("t"), 0.0);
    EXPECT_NO_THROW(capsflow::io::read_checkpoint(out / "checkpoint.h5"));
  }
  EXPECT_EQ(log.find("capsflow: error"), std::string::npos) << log;
}

TEST(Cli, ARestartLogsTheTimeSchemeItContinuesWith) {
  // A restart keeps the checkpoint's time plan and says so; one that changes a key of the plan
  // (time.scheme) resolves it anew and says why. Its log said nothing about the scheme before.
  TempDir d;
  const fs::path out = d.path / "out";
  const Result first = run(std::string("run ") + kTiny + " --set time.t_end=0.02 -o " + out.string(), d.path);
  ASSERT_EQ(first.code, 0) << first.err;
  const std::string scheme = summary_of(out).at("scheme").get<std::string>();  // the plan's
  const Result kept = run("run --restart " + out.string() + " --set time.t_end=0.04 --threads 2", d.path);
  ASSERT_EQ(kept.code, 0) << kept.err;
  EXPECT_NE(kept.out.find("time scheme: " + scheme + " (kept from the checkpoint: "), std::string::npos) << kept.out;
  const Result changed = run("run --restart " + out.string() + " --set time.t_end=0.06 --set time.scheme=heun --threads 2", d.path);
  ASSERT_EQ(changed.code, 0) << changed.err;
  EXPECT_NE(changed.out.find("time scheme: heun (as the scene names it"), std::string::npos) << changed.out;
}
