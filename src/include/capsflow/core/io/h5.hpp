#pragma once
// A small RAII layer over the HDF5 C API (HighFive is not in Debian 12).
//
// - Every identifier is owned by a Handle and closed with its matching H5?close.
// - HDF5's automatic error-stack printing is switched off; a failing call throws
//   IoError with one line naming the file, the object and HDF5's innermost message.
// - Datasets are contiguous, little-endian: float64 for double, int32 for int, int64 for int64.
//   Matrices are stored row-major with shape [rows, cols] (what h5py/numpy and XDMF expect);
//   vectors are 1-D. Strings are fixed-length UTF-8.
// - Names may be paths relative to a group ("steps/000001/positions"); missing intermediate
//   groups are created on write.
// - Attributes live on files and groups (not on datasets): that is all capsflow needs.
#include <hdf5.h>

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "capsflow/core/io/io_error.hpp"

namespace capsflow::io::h5 {

template <typename Scalar>
using RowMatrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatrixXd = RowMatrix<double>;
using RowMatrixXi = RowMatrix<int>;

// Owns one HDF5 identifier. Move-only.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer close) : id_(id), close_(close) {}
  ~Handle() { reset(); }
  Handle(Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept;
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  // Closes now; returns false if HDF5 reported an error (used by File::close to detect failures).
  bool reset() noexcept;

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer close_ = nullptr;
};

// The HDF5 runtime version, e.g. "1.10.8" (recorded in output metadata).
std::string library_version();

class Group;

// What File and Group share: links, datasets and attributes relative to this object.
class Location {
 public:
  hid_t id() const { return handle_.get(); }
  const std::string& file_name() const { return *file_name_; }
  // Absolute path of this object inside the file ("/" for the file itself).
  const std::string& path() const { return path_; }

  bool exists(const std::string& name) const;  // every component of a relative path must exist
  std::vector<std::string> children() const;   // link names directly below, in name order
  bool is_group(const std::string& name) const;

  Group create_group(const std::string& name);  // intermediate groups are created too
  Group open_group(const std::string& name) const;
  Group require_group(const std::string& name);  // open, or create if missing
  void remove(const std::string& name);          // unlink (HDF5 1.10 does not reclaim the space)
  // Copies object `name` (a group with all below it, or a dataset, with their attributes) to
  // `dest_name` in `dest`, which may be in another file; missing intermediate groups are created.
  void copy_to(const std::string& name, Location& dest, const std::string& dest_name) const;

  // Datasets. Writing replaces an existing dataset of the same name.
  template <typename Derived>
  void write_matrix(const std::string& name, const Eigen::DenseBase<Derived>& m) {
    using Scalar = typename Derived::Scalar;
    const Eigen::Ref<const RowMatrix<Scalar>> r(m.derived());
    write_raw(name, native_type<Scalar>(), {hsize_t(r.rows()), hsize_t(r.cols())}, r.data());
  }
  template <typename Derived>
  void write_vector(const std::string& name, const Eigen::DenseBase<Derived>& v) {
    using Scalar = typename Derived::Scalar;
    const Eigen::Matrix<Scalar, Eigen::Dynamic, 1> c = v.derived();  // row or column vector
    write_raw(name, native_type<Scalar>(), {hsize_t(c.size())}, c.data());
  }
  void write_string(const std::string& name, const std::string& text);

  // Reading checks rank and type class (a float dataset is not read as int, nor the reverse).
  template <typename Scalar>
  RowMatrix<Scalar> read_matrix(const std::string& name) const;
  template <typename Scalar>
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> read_vector(const std::string& name) const;
  std::string read_string(const std::string& name) const;
  std::vector<hsize_t> shape(const std::string& name) const;  // dataset dimensions

  // Attributes on this object. Setting replaces an existing attribute.
  void set_attribute(const std::string& name, double value);
  void set_attribute(const std::string& name, std::int64_t value);
  void set_attribute(const std::string& name, int value) {
    set_attribute(name, static_cast<std::int64_t>(value));
  }
  void set_attribute(const std::string& name, const std::string& value);
  void set_attribute(const std::string& name, const char* value) {
    set_attribute(name, std::string(value));
  }
  bool has_attribute(const std::string& name) const;
  double attribute_double(const std::string& name) const;
  std::int64_t attribute_int(const std::string& name) const;
  std::string attribute_string(const std::string& name) const;
  std::vector<std::string> attribute_names() const;

  template <typename Scalar>
  static hid_t native_type();

 protected:
  Location(Handle h, std::shared_ptr<const std::string> file_name, std::string path)
      : handle_(std::move(h)), file_name_(std::move(file_name)), path_(std::move(path)) {}
  // "HDF5: <what> '<object>' in '<file>': <innermost HDF5 message>"
  [[noreturn]] void fail(const std::string& what, const std::string& name) const;
  std::string child_path(const std::string& name) const;

  Handle handle_;
  std::shared_ptr<const std::string> file_name_;
  std::string path_;

 private:
  void write_raw(const std::string& name, hid_t mem_type, const std::vector<hsize_t>& dims,
                 const void* data);
  void read_raw(const std::string& name, hid_t mem_type, H5T_class_t expected_class, int rank,
                std::vector<hsize_t>& dims, std::vector<char>& buffer, std::size_t elem) const;
};

// Defined in h5.cpp; declared here so that the templates above use them (not a generic one).
template <>
hid_t Location::native_type<double>();
template <>
hid_t Location::native_type<int>();
template <>
hid_t Location::native_type<std::int64_t>();

class Group : public Location {
  friend class Location;
  using Location::Location;
};

class File : public Location {
 public:
  enum class Mode { read_only, read_write };

  // Create (truncating any existing file).
  static File create(const std::filesystem::path& path);
  // Open an existing file. With `ignore_lock_conflicts`, a file locked by a reader (ParaView
  // holding run.h5 open) is reopened without HDF5 file locking instead of failing the run.
  static File open(const std::filesystem::path& path, Mode mode = Mode::read_only,
                   bool ignore_lock_conflicts = false);

  void flush();
  // Close now and report failures (the destructor closes silently).
  void close();

 private:
  using Location::Location;
};

}  // namespace capsflow::io::h5
