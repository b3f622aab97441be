// Full-state checkpoints (see checkpoint.hpp).
#include "capsflow/core/io/checkpoint.hpp"

#include <fmt/format.h>

#include <cmath>
#include <functional>
#include <optional>
#include <stdexcept>
#include <system_error>

#include "capsflow/core/io/atomic_file.hpp"
#include "capsflow/core/io/h5.hpp"
#include "capsflow/core/io/input_file.hpp"
#include "capsflow/core/io/run_identity.hpp"
#include "capsflow/core/io/io_error.hpp"
#include "fnv1a.hpp"

namespace capsflow::io {
namespace fs = std::filesystem;

namespace {

constexpr const char* kFormatName = "capsflow-checkpoint";

[[noreturn]] void fail(const std::string& name, const std::string& problem) {
  throw IoError("checkpoint '" + name + "': " + problem);
}

template <typename Derived>
bool all_finite(const Eigen::DenseBase<Derived>& m) {
  return m.size() == 0 || m.derived().array().isFinite().all();
}

// FNV-1a over the state's bytes (fnv1a.hpp): HDF5 (contiguous datasets) has no checksum of its
// own, and a damaged checkpoint must not silently restart a run from wrong numbers.
using detail::Fnv1a;

std::string checksum(const CheckpointState& s) {
  Fnv1a h;
  h.add(&s.step, sizeof s.step);
  h.add(&s.t, sizeof s.t);
  h.add(&s.dt, sizeof s.dt);
  h.add_matrix(s.positions);
  h.add_matrix(s.reference_positions);
  h.add_matrix(s.triangles);
  h.add_matrix(s.wall_state);
  h.add_matrix(s.history);
  if (s.integrator_state.size() > 0) h.add_matrix(s.integrator_state);  // older files have none
  h.add_matrix(s.fluid_state);
  for (const std::string* str : {&s.scene_toml, &s.scene_resolved, &s.version, &s.extra}) {
    h.add_string(*str);
  }
  if (!s.run_id.empty()) h.add_string(s.run_id);  // absent from checkpoints written before run ids
  return h.hex();
}

void write_file(const fs::path& tmp, const CheckpointState& s) {
  h5::File f = h5::File::create(tmp);
  f.set_attribute("format", kFormatName);
  f.set_attribute("format_version", kCheckpointFormatVersion);
  f.set_attribute("step", s.step);
  f.set_attribute("t", s.t);
  f.set_attribute("dt", s.dt);
  f.set_attribute("version", s.version);
  if (!s.run_id.empty()) f.set_attribute("run_id", s.run_id);
  f.set_attribute("mesh_hash", mesh_hash(s.reference_positions, s.triangles));  // for readers; not read back
  f.write_matrix("positions", s.positions);
  f.write_matrix("reference_positions", s.reference_positions);
  f.write_matrix("triangles", s.triangles);
  f.write_vector("wall_state", s.wall_state);
  f.write_matrix("history", s.history);
  f.write_matrix("integrator_state", s.integrator_state);
  f.write_matrix("fluid_state", s.fluid_state);
  f.write_string("scene_toml", s.scene_toml);
  f.write_string("scene_resolved", s.scene_resolved);
  f.write_string("extra", s.extra);
  f.set_attribute("checksum", checksum(s));
  f.close();
}

std::function<void(const fs::path&)>& after_write_hook() {
  static std::function<void(const fs::path&)> hook;
  return hook;
}

// A full disk has produced HDF5 files that closed without an error but held empty strings and
// zeroed arrays: read the temporary back and compare checksums before it may replace anything.
void verify_written(const fs::path& tmp, const CheckpointState& s, const std::string& name) {
  CheckpointState back;
  try {
    back = read_checkpoint(tmp);
  } catch (const std::runtime_error& e) {
    fail(name, std::string("the file just written does not read back (disk full?): ") + e.what());
  }
  if (checksum(back) != checksum(s)) fail(name, "the file just written reads back different numbers (disk full?)");
}

bool reads_as_checkpoint(const fs::path& path) {
  try {
    read_checkpoint(path);
    return true;
  } catch (const std::runtime_error&) {
    return false;
  }
}

}  // namespace

fs::path previous_checkpoint_path(const fs::path& path) {
  fs::path prev = path;
  prev.replace_extension();  // checkpoint.h5 → checkpoint
  prev += ".prev";
  prev += path.extension();
  return prev;
}

void validate_checkpoint(const CheckpointState& s, const std::string& name) {
  const Eigen::Index n = s.positions.rows();
  if (n == 0) fail(name, "no nodes");
  if (s.reference_positions.rows() != n) {
    fail(name, fmt::format("reference_positions has {} rows, positions has {}",
                           s.reference_positions.rows(), n));
  }
  if (s.triangles.rows() == 0) fail(name, "no triangles");
  if (s.triangles.size() > 0 && (s.triangles.minCoeff() < 0 || s.triangles.maxCoeff() >= n)) {
    fail(name, fmt::format("triangle indices outside [0, {})", n));
  }
  if (s.step < 0) fail(name, fmt::format("negative step {}", s.step));
  if (!std::isfinite(s.t)) fail(name, "t is not finite");
  // dt = 0: no step taken yet (a run interrupted before its first step).
  if (!std::isfinite(s.dt) || !(s.dt >= 0)) fail(name, fmt::format("dt = {} is negative or not finite", s.dt));
  if (!all_finite(s.positions)) fail(name, "positions contain NaN or infinity");
  if (!all_finite(s.reference_positions)) fail(name, "reference_positions contain NaN or infinity");
  if (!all_finite(s.wall_state)) fail(name, "wall_state contains NaN or infinity");
  if (!all_finite(s.history)) fail(name, "history contains NaN or infinity");
  if (!all_finite(s.integrator_state)) fail(name, "integrator_state contains NaN or infinity");
  if (!all_finite(s.fluid_state)) fail(name, "fluid_state contains NaN or infinity");
}

void write_checkpoint(const fs::path& path, const CheckpointState& state) {
  validate_checkpoint(state, path.string());
  const fs::path tmp = temporary_sibling(path);
  try {
    write_file(tmp, state);
    fsync_path(tmp);
    if (after_write_hook()) after_write_hook()(tmp);
    verify_written(tmp, state, path.string());
    std::error_code ec;
    // A damaged newest file must not push the last good one out of the previous slot.
    if (fs::exists(path, ec) && reads_as_checkpoint(path)) rename_durably(path, previous_checkpoint_path(path));
    rename_durably(tmp, path);
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);  // best effort; the error being thrown is what matters
    throw;
  }
}

CheckpointState read_checkpoint(const fs::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec)) fail(name, "no such file");
  if (fs::is_directory(path, ec)) fail(name, "is a folder, not a checkpoint file (pass " + (path / kCheckpointFile).string() + ")");
  // A FIFO or a device would block HDF5's open for ever.
  if (const std::string problem = input_file_problem(path.string(), kAnyFileSize); !problem.empty()) fail(name, problem);
  std::optional<h5::File> file;
  try {
    file.emplace(h5::File::open(path, h5::File::Mode::read_only));
  } catch (const std::exception& e) {
    // e.what() starts "HDF5: cannot open file '<path>': <reason>"; keep only the reason.
    std::string why = e.what();
    const std::size_t colon = why.rfind("': ");
    if (colon != std::string::npos) why = why.substr(colon + 3);
    fail(name, "not a readable HDF5 file (truncated or corrupt?): " + why);
  }
  h5::File& f = *file;
  CheckpointState s;
  std::string stored_checksum;
  try {
    if (!f.has_attribute("format") || f.attribute_string("format") != kFormatName) {
      fail(name, "not a capsflow checkpoint (attribute 'format' missing or wrong)");
    }
    const std::int64_t version = f.attribute_int("format_version");
    if (version != kCheckpointFormatVersion) {
      fail(name, fmt::format("format version {} is not supported (this build reads version {})",
                             version, kCheckpointFormatVersion));
    }
    s.step = f.attribute_int("step");
    s.t = f.attribute_double("t");
    s.dt = f.attribute_double("dt");
    s.version = f.attribute_string("version");
    if (f.has_attribute("run_id")) s.run_id = f.attribute_string("run_id");
    const h5::RowMatrixXd x = f.read_matrix<double>("positions");
    const h5::RowMatrixXd x0 = f.read_matrix<double>("reference_positions");
    const h5::RowMatrixXi tri = f.read_matrix<int>("triangles");
    if (x.cols() != 3) fail(name, fmt::format("positions has {} columns, expected 3", x.cols()));
    if (x0.cols() != 3) {
      fail(name, fmt::format("reference_positions has {} columns, expected 3", x0.cols()));
    }
    if (tri.cols() != 3)
      fail(name, fmt::format("triangles has {} columns, expected 3", tri.cols()));
    s.positions = x;
    s.reference_positions = x0;
    s.triangles = tri;
    s.wall_state = f.read_vector<double>("wall_state");
    s.history = f.read_matrix<double>("history");
    if (f.exists("integrator_state")) s.integrator_state = f.read_matrix<double>("integrator_state");
    s.fluid_state = f.read_matrix<double>("fluid_state");
    s.scene_toml = f.read_string("scene_toml");
    s.scene_resolved = f.read_string("scene_resolved");
    s.extra = f.read_string("extra");
    stored_checksum = f.attribute_string("checksum");
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    if (what.rfind("checkpoint '", 0) == 0) throw;
    fail(name, what);  // an HDF5 read error: missing dataset, wrong type, damaged data
  }
  // Shapes and values first (the more specific message), then the bytes.
  validate_checkpoint(s, name);
  if (stored_checksum != checksum(s)) fail(name, "checksum mismatch: the file is damaged");
  return s;
}

LoadedCheckpoint load_checkpoint_for_restart(const fs::path& given) {
  std::error_code ec;
  const fs::path path = fs::is_directory(given, ec) ? given / kCheckpointFile : given;
  LoadedCheckpoint out;
  out.path = path;
  try {
    out.state = read_checkpoint(path);
    return out;
  } catch (const std::runtime_error& e) {
    const fs::path prev = previous_checkpoint_path(path);
    if (path.filename() != kCheckpointFile || !fs::exists(prev, ec)) throw;
    try {
      out.state = read_checkpoint(prev);
    } catch (const std::runtime_error& e2) {
      throw IoError(std::string(e.what()) + "; the previous one is not usable either: " + e2.what());
    }
    out.path = prev;
    out.fallback_reason = e.what();
    return out;
  }
}

void set_checkpoint_write_hook_for_tests(std::function<void(const fs::path& tmp)> hook) { after_write_hook() = std::move(hook); }

fs::path find_latest_checkpoint(const fs::path& folder) {
  const fs::path latest = folder / kCheckpointFile;
  const fs::path prev = previous_checkpoint_path(latest);
  std::string why;
  for (const fs::path& p : {latest, prev}) {
    try {
      read_checkpoint(p);
      return p;
    } catch (const std::runtime_error& e) {
      why += (why.empty() ? "" : "; ") + std::string(e.what());
    }
  }
  throw IoError("no usable checkpoint in '" + folder.string() + "': " + why);
}

}  // namespace capsflow::io
