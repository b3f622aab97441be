#pragma once
// What produced a result: capsflow version, git hash, build, and dependency versions.
#include <nlohmann/json_fwd.hpp>
#include <string>

namespace capsflow {

const char* git_hash();  // generated at build time (cmake/git_hash.cmake)
std::string version_string();           // e.g. "0.1.0"
nlohmann::json build_info();            // version, git hash, compiler, flags, dependency versions

}  // namespace capsflow
