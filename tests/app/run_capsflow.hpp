#pragma once
// Helpers of the end-to-end tests that run the capsflow executable (CAPSFLOW_EXE): a scratch
// folder per test process, `capsflow run` with its output in DIR.log, readers of summary.json
// and timeseries.csv, and a process in the background with a bounded wait for it.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace capsflow_test {

namespace fs = std::filesystem;

inline fs::path scratch(const std::string& suite, const std::string& name) {
  return fs::temp_directory_path() / ("capsflow-" + suite + "-" + std::to_string(::getpid()) + "-" + name);
}

// `capsflow run ARGS -o DIR --overwrite --threads 2`, stdout and stderr in DIR.log; the exit code.
inline int run(const std::string& args, const fs::path& dir) {
  const std::string cmd = std::string(CAPSFLOW_EXE) + " run " + args + " -o " + dir.string() + " --overwrite --threads 2 > " +
                          dir.string() + ".log 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline nlohmann::json json_of(const fs::path& p) { return nlohmann::json::parse(slurp(p)); }
inline nlohmann::json summary(const fs::path& dir) { return json_of(dir / "summary.json"); }

// timeseries.csv as rows of column → value (an empty field reads as 0).
inline std::vector<std::map<std::string, double>> series_rows(const fs::path& dir) {
  std::ifstream in(dir / "timeseries.csv");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream hs(line);
  for (std::string c; std::getline(hs, c, ',');) names.push_back(c);
  std::vector<std::map<std::string, double>> out;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::map<std::string, double> row;
    std::string c;
    for (size_t k = 0; k < names.size() && std::getline(ls, c, ','); ++k) row[names[k]] = std::atof(c.c_str());
    out.push_back(row);
  }
  return out;
}

// Any capsflow command line; stdout and stderr together in DIR/log.txt (spdlog writes both levels
// to stdout). With `cwd`, run from that folder (relative paths in args are relative to it).
struct Result {
  int code;
  std::string out;
};
inline Result capsflow(const std::string& args, const fs::path& dir, const fs::path& cwd = {}) {
  const fs::path log = dir / "log.txt";
  const std::string cd = cwd.empty() ? std::string() : "cd '" + cwd.string() + "' && ";
  const std::string cmd = cd + std::string(CAPSFLOW_EXE) + " " + args + " > " + log.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream in(log);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, std::string(std::istreambuf_iterator<char>(in), {})};
}

// A fresh folder named after the suite, the process and the running test; removed at the end.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& suite)
      : path(fs::temp_directory_path() / ("capsflow-" + suite + "-" + std::to_string(::getpid()) + "-" +
                                          ::testing::UnitTest::GetInstance()->current_test_info()->name())) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

// `capsflow ARGS` started in the background, stdout and stderr in LOG; its pid.
inline pid_t spawn(const std::string& args, const fs::path& log) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const std::string cmd = "exec " + std::string(CAPSFLOW_EXE) + " " + args + " > '" + log.string() + "' 2>&1";
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

// Waits up to `seconds` for `pid`; its exit code (128 + the signal that ended it), or -1 after
// killing it with SIGKILL (a hang).
inline int wait_or_kill(pid_t pid, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int status = 0;
  while (std::chrono::steady_clock::now() < end) {
    if (::waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &status, 0);
  return -1;
}

// Waits up to `seconds` until `ready()`; whether it became true.
template <class Ready>
bool wait_until(Ready ready, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!ready()) {
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

inline void remove_run(const fs::path& p) {
  fs::remove_all(p);
  fs::remove(p.string() + ".log");
}

}  // namespace capsflow_test
