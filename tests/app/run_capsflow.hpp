#pragma once
// Helpers of the end-to-end tests that run the capsflow executable (CAPSFLOW_EXE): a scratch
// folder per test process, `capsflow run` with its output in DIR.log, and readers of summary.json
// and timeseries.csv.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
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

inline void remove_run(const fs::path& p) {
  fs::remove_all(p);
  fs::remove(p.string() + ".log");
}

}  // namespace capsflow_test
