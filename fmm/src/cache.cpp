#include "capsflow/fmm/cache.hpp"

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace capsflow::fmm {
namespace {
constexpr char kMagic[8] = {'C', 'F', 'F', 'M', 'M', 'O', 'P', '\1'};
constexpr std::uint32_t kVersion = 2;  // 2: pseudo-inverses stored as SVD factors

std::uint64_t fnv1a(const void* data, std::size_t n, std::uint64_t h) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ULL;
  }
  return h;
}
}  // namespace

std::string resolve_cache_dir(const std::string& requested) {
  if (!requested.empty()) return requested;
  if (const char* d = std::getenv("CAPSFLOW_CACHE_DIR"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return std::string(d) + "/capsflow";
  if (const char* d = std::getenv("HOME"); d && *d) return std::string(d) + "/.cache/capsflow";
  return "";
}

bool load_operator_cache(const std::string& path, const std::string& key,
                         std::vector<Eigen::MatrixXd>& mats) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  char magic[8];
  std::uint32_t version = 0, keylen = 0, count = 0;
  if (!in.read(magic, 8) || std::memcmp(magic, kMagic, 8) != 0) return false;
  if (!in.read(reinterpret_cast<char*>(&version), 4) || version != kVersion) return false;
  if (!in.read(reinterpret_cast<char*>(&keylen), 4) || keylen != key.size()) return false;
  std::string k(keylen, '\0');
  if (!in.read(k.data(), keylen) || k != key) return false;
  if (!in.read(reinterpret_cast<char*>(&count), 4) || count > 1000) return false;
  std::vector<Eigen::MatrixXd> out(count);
  std::uint64_t h = 14695981039346656037ULL;
  for (auto& m : out) {
    std::int64_t rc[2];
    if (!in.read(reinterpret_cast<char*>(rc), 16)) return false;
    if (rc[0] < 0 || rc[1] < 0 || rc[0] > (1 << 20) || rc[1] > (1 << 20)) return false;
    m.resize(rc[0], rc[1]);
    const std::size_t bytes = sizeof(double) * static_cast<std::size_t>(m.size());
    if (!in.read(reinterpret_cast<char*>(m.data()), static_cast<std::streamsize>(bytes))) return false;
    h = fnv1a(rc, 16, h);
    h = fnv1a(m.data(), bytes, h);
  }
  std::uint64_t stored = 0;
  if (!in.read(reinterpret_cast<char*>(&stored), 8) || stored != h) return false;
  if (in.peek() != std::ifstream::traits_type::eof()) return false;  // trailing garbage
  mats = std::move(out);
  return true;
}

bool save_operator_cache(const std::string& path, const std::string& key,
                         const std::vector<Eigen::MatrixXd>& mats) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path p(path);
  if (p.has_parent_path()) fs::create_directories(p.parent_path(), ec);
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return false;
    const std::uint32_t keylen = static_cast<std::uint32_t>(key.size());
    const std::uint32_t count = static_cast<std::uint32_t>(mats.size());
    out.write(kMagic, 8);
    out.write(reinterpret_cast<const char*>(&kVersion), 4);
    out.write(reinterpret_cast<const char*>(&keylen), 4);
    out.write(key.data(), keylen);
    out.write(reinterpret_cast<const char*>(&count), 4);
    std::uint64_t h = 14695981039346656037ULL;
    for (const auto& m : mats) {
      const std::int64_t rc[2] = {m.rows(), m.cols()};
      const std::size_t bytes = sizeof(double) * static_cast<std::size_t>(m.size());
      out.write(reinterpret_cast<const char*>(rc), 16);
      out.write(reinterpret_cast<const char*>(m.data()), static_cast<std::streamsize>(bytes));
      h = fnv1a(rc, 16, h);
      h = fnv1a(m.data(), bytes, h);
    }
    out.write(reinterpret_cast<const char*>(&h), 8);
    out.flush();
    if (!out) { fs::remove(tmp, ec); return false; }
  }
  fs::rename(tmp, path, ec);
  if (ec) { fs::remove(tmp, ec); return false; }
  return true;
}

}  // namespace capsflow::fmm
