// RAII layer over the HDF5 C API (see h5.hpp).
#include "capsflow/core/io/h5.hpp"
#include "capsflow/core/io/io_error.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <stdexcept>

namespace capsflow::io::h5 {
namespace fs = std::filesystem;

namespace {

// HDF5 prints its whole error stack to stderr by default; we report errors as exceptions instead.
// Also keeps HDF5 from closing its files in an atexit handler: after a failed H5Fclose (a full
// disk) that handler retried the close and crashed (exit 139 instead of capsflow's one-line
// error and exit 1). Every file capsflow writes is closed explicitly (File::close), so nothing is
// lost. H5dont_atexit must come before the library initialises, i.e. before any other call.
// (Also run at static initialisation, before anything can open the library.)
const bool kNoAtexit = H5dont_atexit() >= 0;
void silence_hdf5_errors() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

herr_t innermost_message(unsigned n, const H5E_error2_t* e, void* out) {
  // Walking upward, n == 0 is the most specific error (e.g. "truncated file: eof = ...").
  if (n == 0 && e->desc != nullptr) *static_cast<std::string*>(out) = e->desc;
  return 0;
}

// The innermost message of the current thread's HDF5 error stack (read before the next call).
// System-call failures come as "file write failed: time = <ctime with a newline>, filename = ...,
// errno = 28, error message = 'No space left on device', buf = ..."; keep the operation and the
// system's message, so that the error stays one readable line.
std::string hdf5_message() {
  std::string msg;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, innermost_message, &msg);
  H5Eclear2(H5E_DEFAULT);
  if (msg.empty()) return "unknown HDF5 error";
  const std::string key = "error message = '";
  const std::size_t at = msg.find(key);
  if (at != std::string::npos) {
    const std::size_t end = msg.find('\'', at + key.size());
    std::string what = msg.substr(0, std::min(msg.find_first_of(":,"), at));
    while (!what.empty() && (what.back() == ' ' || what.back() == ',')) what.pop_back();
    msg = what + ": " + msg.substr(at + key.size(), end == std::string::npos ? std::string::npos : end - at - key.size());
  }
  for (char& c : msg)
    if (c == '\n' || c == '\r') c = ' ';
  return msg;
}

[[noreturn]] void fail_file(const std::string& what, const fs::path& path) {
  const std::string msg = hdf5_message();
  throw IoError("HDF5: " + what + " '" + path.string() + "': " + msg);
}

std::vector<std::string> split_path(const std::string& name) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (start <= name.size()) {
    const std::size_t end = name.find('/', start);
    const std::string part = name.substr(start, end == std::string::npos ? end : end - start);
    if (!part.empty() && part != ".") parts.push_back(part);
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return parts;
}

Handle property_list(hid_t cls) { return Handle(H5Pcreate(cls), H5Pclose); }

// Link-creation list that creates missing intermediate groups.
Handle intermediate_lcpl() {
  Handle lcpl = property_list(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  return lcpl;
}

Handle string_type(std::size_t length) {
  Handle t(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(t.get(), length + 1);  // +1: room for the terminator (and length 0 is invalid)
  H5Tset_strpad(t.get(), H5T_STR_NULLTERM);
  H5Tset_cset(t.get(), H5T_CSET_UTF8);
  return t;
}

// Read a fixed-length string given its file type and a reader for a memory type.
template <typename ReadFn>
std::string read_fixed_string(hid_t file_type, ReadFn read, bool& ok) {
  ok = false;
  if (H5Tget_class(file_type) != H5T_STRING || H5Tis_variable_str(file_type) > 0) return {};
  const std::size_t size = H5Tget_size(file_type);
  Handle mem(H5Tcopy(file_type), H5Tclose);
  std::vector<char> buf(size + 1, '\0');
  if (read(mem.get(), buf.data()) < 0) return {};
  ok = true;
  return std::string(buf.data(), strnlen(buf.data(), size));
}

}  // namespace

Handle& Handle::operator=(Handle&& o) noexcept {
  if (this != &o) {
    reset();
    id_ = o.id_;
    close_ = o.close_;
    o.id_ = H5I_INVALID_HID;
  }
  return *this;
}

bool Handle::reset() noexcept {
  bool ok = true;
  if (id_ >= 0 && close_ != nullptr) ok = close_(id_) >= 0;
  id_ = H5I_INVALID_HID;
  return ok;
}

std::string library_version() {
  unsigned major = 0, minor = 0, release = 0;
  H5get_libversion(&major, &minor, &release);
  return std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(release);
}

template <>
hid_t Location::native_type<double>() {
  return H5T_NATIVE_DOUBLE;
}
template <>
hid_t Location::native_type<int>() {
  return H5T_NATIVE_INT;
}
template <>
hid_t Location::native_type<std::int64_t>() {
  return H5T_NATIVE_INT64;
}

// ---- Location ----

void Location::fail(const std::string& what, const std::string& name) const {
  const std::string msg = hdf5_message();
  throw IoError("HDF5: " + what + " '" + child_path(name) + "' in '" + file_name() +
                           "': " + msg);
}

std::string Location::child_path(const std::string& name) const {
  if (name.empty()) return path_;
  if (name.front() == '/') return name;
  return path_ == "/" ? "/" + name : path_ + "/" + name;
}

bool Location::exists(const std::string& name) const {
  std::string prefix = !name.empty() && name.front() == '/' ? "/" : "";
  for (const std::string& part : split_path(name)) {
    prefix += prefix.empty() || prefix == "/" ? part : "/" + part;
    const htri_t r = H5Lexists(id(), prefix.c_str(), H5P_DEFAULT);
    if (r < 0) fail("cannot check existence of", prefix);
    if (r == 0) return false;
  }
  return true;
}

bool Location::is_group(const std::string& name) const {
  if (!exists(name)) return false;
  // H5Oopen + H5Iget_type rather than H5Oget_info_by_name, whose signature changed in HDF5 1.12.
  const Handle obj(H5Oopen(id(), name.c_str(), H5P_DEFAULT), H5Oclose);
  if (!obj.valid()) fail("cannot open object", name);
  return H5Iget_type(obj.get()) == H5I_GROUP;
}

std::vector<std::string> Location::children() const {
  std::vector<std::string> names;
  auto collect = [](hid_t, const char* n, const H5L_info_t*, void* out) -> herr_t {
    static_cast<std::vector<std::string>*>(out)->emplace_back(n);
    return 0;
  };
  hsize_t idx = 0;
  if (H5Literate(id(), H5_INDEX_NAME, H5_ITER_INC, &idx, collect, &names) < 0) {
    fail("cannot list the children of", "");
  }
  return names;
}

Group Location::create_group(const std::string& name) {
  const Handle lcpl = intermediate_lcpl();
  const hid_t g = H5Gcreate2(id(), name.c_str(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT);
  if (g < 0) fail("cannot create group", name);
  return Group(Handle(g, H5Gclose), file_name_, child_path(name));
}

Group Location::open_group(const std::string& name) const {
  const hid_t g = H5Gopen2(id(), name.c_str(), H5P_DEFAULT);
  if (g < 0) fail("cannot open group", name);
  return Group(Handle(g, H5Gclose), file_name_, child_path(name));
}

Group Location::require_group(const std::string& name) {
  return exists(name) ? open_group(name) : create_group(name);
}

void Location::remove(const std::string& name) {
  if (H5Ldelete(id(), name.c_str(), H5P_DEFAULT) < 0) fail("cannot remove", name);
}

void Location::copy_to(const std::string& name, Location& dest, const std::string& dest_name) const {
  const Handle lcpl = intermediate_lcpl();
  if (H5Ocopy(id(), name.c_str(), dest.id(), dest_name.c_str(), H5P_DEFAULT, lcpl.get()) < 0) {
    fail("cannot copy", name);
  }
}

void Location::write_raw(const std::string& name, hid_t mem_type, const std::vector<hsize_t>& dims,
                         const void* data) {
  if (exists(name)) remove(name);
  hid_t file_type = H5T_IEEE_F64LE;
  if (mem_type == H5T_NATIVE_INT) file_type = H5T_STD_I32LE;
  if (mem_type == H5T_NATIVE_INT64) file_type = H5T_STD_I64LE;
  const Handle space(H5Screate_simple(int(dims.size()), dims.data(), nullptr), H5Sclose);
  if (!space.valid()) fail("cannot create dataspace for", name);
  const Handle lcpl = intermediate_lcpl();
  const Handle ds(
      H5Dcreate2(id(), name.c_str(), file_type, space.get(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT),
      H5Dclose);
  if (!ds.valid()) fail("cannot create dataset", name);
  hsize_t count = 1;
  for (hsize_t d : dims) count *= d;
  // An empty dataset has no data to write (and HDF5 rejects a null buffer).
  if (count > 0 && H5Dwrite(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    fail("cannot write dataset", name);
  }
}

void Location::write_string(const std::string& name, const std::string& text) {
  if (exists(name)) remove(name);
  const Handle type = string_type(text.size());
  const Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  const Handle lcpl = intermediate_lcpl();
  const Handle ds(
      H5Dcreate2(id(), name.c_str(), type.get(), space.get(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT),
      H5Dclose);
  if (!ds.valid()) fail("cannot create string dataset", name);
  if (H5Dwrite(ds.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, text.c_str()) < 0) {
    fail("cannot write string dataset", name);
  }
}

std::vector<hsize_t> Location::shape(const std::string& name) const {
  const Handle ds(H5Dopen2(id(), name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.valid()) fail("cannot open dataset", name);
  const Handle space(H5Dget_space(ds.get()), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0) fail("cannot read the shape of", name);
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

void Location::read_raw(const std::string& name, hid_t mem_type, H5T_class_t expected_class,
                        int rank, std::vector<hsize_t>& dims, std::vector<char>& buffer,
                        std::size_t elem) const {
  const Handle ds(H5Dopen2(id(), name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.valid()) fail("cannot open dataset", name);
  const Handle type(H5Dget_type(ds.get()), H5Tclose);
  if (H5Tget_class(type.get()) != expected_class) {
    throw IoError("HDF5: dataset '" + child_path(name) + "' in '" + file_name() +
                             "' has the wrong type (expected " +
                             (expected_class == H5T_FLOAT ? "float" : "integer") + ")");
  }
  const Handle space(H5Dget_space(ds.get()), H5Sclose);
  const int r = H5Sget_simple_extent_ndims(space.get());
  if (r != rank) {
    throw IoError("HDF5: dataset '" + child_path(name) + "' in '" + file_name() +
                             "' has rank " + std::to_string(r) + ", expected " +
                             std::to_string(rank));
  }
  dims.assign(static_cast<std::size_t>(rank), 0);
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  hsize_t count = 1;
  for (hsize_t d : dims) count *= d;
  buffer.assign(count * elem, 0);
  if (count > 0 && H5Dread(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer.data()) < 0) {
    fail("cannot read dataset", name);
  }
}

template <typename Scalar>
RowMatrix<Scalar> Location::read_matrix(const std::string& name) const {
  std::vector<hsize_t> dims;
  std::vector<char> buf;
  const H5T_class_t cls = std::is_floating_point_v<Scalar> ? H5T_FLOAT : H5T_INTEGER;
  read_raw(name, native_type<Scalar>(), cls, 2, dims, buf, sizeof(Scalar));
  RowMatrix<Scalar> m(static_cast<Eigen::Index>(dims[0]), static_cast<Eigen::Index>(dims[1]));
  if (m.size() > 0) std::memcpy(m.data(), buf.data(), buf.size());
  return m;
}

template <typename Scalar>
Eigen::Matrix<Scalar, Eigen::Dynamic, 1> Location::read_vector(const std::string& name) const {
  std::vector<hsize_t> dims;
  std::vector<char> buf;
  const H5T_class_t cls = std::is_floating_point_v<Scalar> ? H5T_FLOAT : H5T_INTEGER;
  read_raw(name, native_type<Scalar>(), cls, 1, dims, buf, sizeof(Scalar));
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> v(static_cast<Eigen::Index>(dims[0]));
  if (v.size() > 0) std::memcpy(v.data(), buf.data(), buf.size());
  return v;
}

template RowMatrix<double> Location::read_matrix<double>(const std::string&) const;
template RowMatrix<int> Location::read_matrix<int>(const std::string&) const;
template RowMatrix<std::int64_t> Location::read_matrix<std::int64_t>(const std::string&) const;
template Eigen::VectorXd Location::read_vector<double>(const std::string&) const;
template Eigen::VectorXi Location::read_vector<int>(const std::string&) const;
template Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1> Location::read_vector<std::int64_t>(
    const std::string&) const;

std::string Location::read_string(const std::string& name) const {
  const Handle ds(H5Dopen2(id(), name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.valid()) fail("cannot open dataset", name);
  const Handle type(H5Dget_type(ds.get()), H5Tclose);
  bool ok = false;
  std::string s = read_fixed_string(
      type.get(),
      [&](hid_t mem, char* buf) {
        return H5Dread(ds.get(), mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
      },
      ok);
  if (!ok) fail("cannot read as a fixed-length string the dataset", name);
  return s;
}

// ---- attributes ----

namespace {
Handle create_attribute(hid_t obj, const std::string& name, hid_t type) {
  if (H5Aexists(obj, name.c_str()) > 0) H5Adelete(obj, name.c_str());
  const Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  return Handle(H5Acreate2(obj, name.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                H5Aclose);
}
}  // namespace

void Location::set_attribute(const std::string& name, double value) {
  const Handle a = create_attribute(id(), name, H5T_IEEE_F64LE);
  if (!a.valid() || H5Awrite(a.get(), H5T_NATIVE_DOUBLE, &value) < 0) {
    fail("cannot write attribute '" + name + "' of", "");
  }
}

void Location::set_attribute(const std::string& name, std::int64_t value) {
  const Handle a = create_attribute(id(), name, H5T_STD_I64LE);
  if (!a.valid() || H5Awrite(a.get(), H5T_NATIVE_INT64, &value) < 0) {
    fail("cannot write attribute '" + name + "' of", "");
  }
}

void Location::set_attribute(const std::string& name, const std::string& value) {
  const Handle type = string_type(value.size());
  const Handle a = create_attribute(id(), name, type.get());
  if (!a.valid() || H5Awrite(a.get(), type.get(), value.c_str()) < 0) {
    fail("cannot write attribute '" + name + "' of", "");
  }
}

bool Location::has_attribute(const std::string& name) const {
  const htri_t r = H5Aexists(id(), name.c_str());
  if (r < 0) fail("cannot check attribute '" + name + "' of", "");
  return r > 0;
}

namespace {
Handle open_attribute(const Location& loc, const std::string& name) {
  return Handle(H5Aopen(loc.id(), name.c_str(), H5P_DEFAULT), H5Aclose);
}
}  // namespace

double Location::attribute_double(const std::string& name) const {
  const Handle a = open_attribute(*this, name);
  double v = 0;
  if (!a.valid()) fail("missing attribute '" + name + "' on", "");
  const Handle type(H5Aget_type(a.get()), H5Tclose);
  const H5T_class_t cls = H5Tget_class(type.get());
  if ((cls != H5T_FLOAT && cls != H5T_INTEGER) || H5Aread(a.get(), H5T_NATIVE_DOUBLE, &v) < 0) {
    fail("cannot read as a number the attribute '" + name + "' of", "");
  }
  return v;
}

std::int64_t Location::attribute_int(const std::string& name) const {
  const Handle a = open_attribute(*this, name);
  std::int64_t v = 0;
  if (!a.valid()) fail("missing attribute '" + name + "' on", "");
  const Handle type(H5Aget_type(a.get()), H5Tclose);
  if (H5Tget_class(type.get()) != H5T_INTEGER || H5Aread(a.get(), H5T_NATIVE_INT64, &v) < 0) {
    fail("cannot read as an integer the attribute '" + name + "' of", "");
  }
  return v;
}

std::string Location::attribute_string(const std::string& name) const {
  const Handle a = open_attribute(*this, name);
  if (!a.valid()) fail("missing attribute '" + name + "' on", "");
  const Handle type(H5Aget_type(a.get()), H5Tclose);
  bool ok = false;
  std::string s = read_fixed_string(
      type.get(), [&](hid_t mem, char* buf) { return H5Aread(a.get(), mem, buf); }, ok);
  if (!ok) fail("cannot read as a string the attribute '" + name + "' of", "");
  return s;
}

std::vector<std::string> Location::attribute_names() const {
  std::vector<std::string> names;
  auto collect = [](hid_t, const char* n, const H5A_info_t*, void* out) -> herr_t {
    static_cast<std::vector<std::string>*>(out)->emplace_back(n);
    return 0;
  };
  hsize_t idx = 0;
  if (H5Aiterate2(id(), H5_INDEX_NAME, H5_ITER_INC, &idx, collect, &names) < 0) {
    fail("cannot list the attributes of", "");
  }
  return names;
}

// ---- File ----

File File::create(const fs::path& path) {
  silence_hdf5_errors();
  const hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (f < 0) fail_file("cannot create file", path);
  return File(Handle(f, H5Fclose), std::make_shared<const std::string>(path.string()), "/");
}

File File::open(const fs::path& path, Mode mode, bool ignore_lock_conflicts) {
  silence_hdf5_errors();
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    throw IoError("HDF5: cannot open file '" + path.string() + "': no such file");
  }
  const unsigned flags = mode == Mode::read_write ? H5F_ACC_RDWR : H5F_ACC_RDONLY;
  hid_t f = H5Fopen(path.c_str(), flags, H5P_DEFAULT);
  if (f < 0) {
    const std::string msg = hdf5_message();
    if (!ignore_lock_conflicts || msg.find("lock") == std::string::npos) {
      throw IoError("HDF5: cannot open file '" + path.string() + "': " + msg);
    }
#if H5_VERSION_GE(1, 10, 7)  // H5Pset_file_locking appeared in 1.10.7
    // A reader holds the file (HDF5 >= 1.10 locking). Losing hours of run time is worse than a
    // reader that may see a half-written step and must reload, so write without the lock.
    static std::atomic<bool> warned{false};  // once per run, not at every output step
    if (!warned.exchange(true)) {
      spdlog::warn("{} is locked by another program (ParaView?); writing without HDF5 file locking",
                   path.string());
    }
    const Handle fapl = property_list(H5P_FILE_ACCESS);
    H5Pset_file_locking(fapl.get(), 0, 1);
    f = H5Fopen(path.c_str(), flags, fapl.get());
    if (f < 0) fail_file("cannot open file", path);
#else
    throw IoError("HDF5: cannot open file '" + path.string() + "': " + msg +
                             " (set HDF5_USE_FILE_LOCKING=FALSE to write while it is read)");
#endif
  }
  return File(Handle(f, H5Fclose), std::make_shared<const std::string>(path.string()), "/");
}

void File::flush() {
  if (H5Fflush(id(), H5F_SCOPE_LOCAL) < 0) fail_file("cannot flush file", file_name());
}

void File::close() {
  if (!handle_.reset()) fail_file("cannot close file", file_name());
}

}  // namespace capsflow::io::h5
