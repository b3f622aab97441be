#pragma once
// Private helper of src/io: FNV-1a 64 over bytes, Eigen matrices (with their shape) and strings.
// Used for the checkpoint checksum and the mesh hash of a run's identity.
#include <fmt/format.h>

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>

namespace capsflow::io::detail {

class Fnv1a {
 public:
  void add(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 0x100000001b3ULL;
  }
  template <typename Derived>
  void add_matrix(const Eigen::PlainObjectBase<Derived>& m) {
    const std::int64_t shape[2] = {m.rows(), m.cols()};
    add(shape, sizeof shape);
    add(m.data(), sizeof(typename Derived::Scalar) * std::size_t(m.size()));
  }
  void add_string(const std::string& s) {
    const std::uint64_t n = s.size();
    add(&n, sizeof n);
    add(s.data(), s.size());
  }
  std::string hex() const { return fmt::format("{:016x}", h_); }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

}  // namespace capsflow::io::detail
