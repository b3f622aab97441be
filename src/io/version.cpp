#include "capsflow/core/io/version.hpp"

#include <H5public.h>
#include <fmt/core.h>
#include <spdlog/version.h>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <toml++/toml.h>

namespace capsflow {
namespace fmm {
std::string fftw_version_string();
}

std::string version_string() { return CAPSFLOW_VERSION; }

nlohmann::json build_info() {
  unsigned h5maj = 0, h5min = 0, h5rel = 0;
  H5get_libversion(&h5maj, &h5min, &h5rel);
  nlohmann::json deps = {
      {"eigen", fmt::format("{}.{}.{}", EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION)},
      {"fftw", fmm::fftw_version_string()},
      {"hdf5", fmt::format("{}.{}.{}", h5maj, h5min, h5rel)},
      {"openmp", fmt::format("{}", _OPENMP)},
      {"tomlplusplus", fmt::format("{}.{}.{}", TOML_LIB_MAJOR, TOML_LIB_MINOR, TOML_LIB_PATCH)},
      {"nlohmann_json", fmt::format("{}.{}.{}", NLOHMANN_JSON_VERSION_MAJOR, NLOHMANN_JSON_VERSION_MINOR, NLOHMANN_JSON_VERSION_PATCH)},
      {"fmt", fmt::format("{}", FMT_VERSION)},
      {"spdlog", fmt::format("{}.{}.{}", SPDLOG_VER_MAJOR, SPDLOG_VER_MINOR, SPDLOG_VER_PATCH)},
  };
  return {{"version", version_string()},
          {"git", git_hash()},
          {"compiler", std::string(__VERSION__)},
#ifdef __AVX512F__
          {"simd", "avx512"},
#elif defined(__AVX2__)
          {"simd", "avx2"},
#else
          {"simd", "baseline"},
#endif
#ifdef NDEBUG
          {"build", "release"},
#else
          {"build", "debug"},
#endif
          {"dependencies", deps}};
}

}  // namespace capsflow
