// Output folder preparation (see output_folder.hpp).
#include "capsflow/core/io/output_folder.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <system_error>

namespace capsflow::io {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& msg) { throw std::runtime_error(msg); }

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

bool starts_with(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

bool is_capsflow_output_name(const std::string& name) {
  // Leftover temporaries of an atomic write ("run.xmf.tmp.1234") belong to us too.
  const std::size_t tmp = name.find(".tmp.");
  const std::string base = tmp == std::string::npos ? name : name.substr(0, tmp);
  if (tmp != std::string::npos) {
    const std::string pid = name.substr(tmp + 5);
    if (pid.empty() ||
        !std::all_of(pid.begin(), pid.end(), [](char c) { return c >= '0' && c <= '9'; }))
      return false;
  }
  static const char* const fixed[] = {"run.h5",       "run.xmf", "timeseries.csv",
                                      "summary.json", "log",     "capsflow.log"};
  for (const char* f : fixed) {
    if (base == f) return true;
  }
  return starts_with(base, "checkpoint") && ends_with(base, ".h5");
}

void check_writable(const fs::path& dir) {
  const fs::path probe = dir / (".capsflow-write-probe." + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    fail("output folder " + quoted(dir) + " is not writable: " + std::strerror(errno));
  }
  ::close(fd);
  if (::unlink(probe.c_str()) != 0) {
    fail("output folder " + quoted(dir) +
         " is not writable: cannot remove a probe file: " + std::strerror(errno));
  }
}

PreparedFolder prepare_output_folder(const fs::path& dir, bool overwrite) {
  if (dir.empty()) fail("the output folder path is empty");
  PreparedFolder out{dir, {}, {}};
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (fs::exists(st)) {
    if (!fs::is_directory(st)) fail("output path " + quoted(dir) + " exists and is not a folder");
    std::vector<fs::directory_entry> entries;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      entries.push_back(*it);
    }
    if (ec) fail("cannot list output folder " + quoted(dir) + ": " + ec.message());
    if (!entries.empty() && !overwrite) {
      fail("output folder " + quoted(dir) +
           " exists and is not empty; pass --overwrite to replace it");
    }
    // Probe first: with a read-only folder we must fail before deleting anything.
    check_writable(dir);
    for (const fs::directory_entry& e : entries) {
      const bool ours = is_capsflow_output_name(e.path().filename().string()) &&
                        !e.is_directory(ec) && !e.is_symlink(ec);
      if (!ours) {
        out.kept.push_back(e.path());
        continue;
      }
      if (!fs::remove(e.path(), ec) || ec) {
        fail("cannot remove " + quoted(e.path()) + " from output folder: " + ec.message());
      }
      out.removed.push_back(e.path());
    }
    std::sort(out.removed.begin(), out.removed.end());
    std::sort(out.kept.begin(), out.kept.end());
    return out;
  }
  fs::create_directories(dir, ec);
  if (ec) fail("cannot create output folder " + quoted(dir) + ": " + ec.message());
  check_writable(dir);
  return out;
}

PreparedFolder open_output_folder_for_restart(const fs::path& dir) {
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (!fs::exists(st))
    fail("cannot restart in output folder " + quoted(dir) + ": it does not exist");
  if (!fs::is_directory(st)) fail("output path " + quoted(dir) + " exists and is not a folder");
  check_writable(dir);
  return PreparedFolder{dir, {}, {}};
}

}  // namespace capsflow::io
