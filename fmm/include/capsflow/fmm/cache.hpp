#pragma once
// capsflow::fmm cache — on-disk storage of precomputed operators (one file per kernel/order/precision).
//
// File name: <kernel>_p<order>_f64.bin in the cache directory. Format (little-endian, native):
//   8-byte magic "CFFMMOP\1", uint32 format version, then a text key line (kernel, order, surface
//   size, component counts, radii, regularisation, precision) that must match exactly, then the
//   matrix count, each matrix's rows and cols, the payload (doubles, column-major) and an FNV-1a
//   64-bit checksum of the payload. Any mismatch, truncation or checksum failure => the file is
//   ignored and rebuilt (never trusted). Files are written to a temporary name and renamed
//   (atomic on POSIX), so a crash never leaves a half-written cache under the final name.
#include <Eigen/Dense>
#include <string>
#include <vector>

namespace capsflow::fmm {

/// "" -> $CAPSFLOW_CACHE_DIR, else $XDG_CACHE_HOME/capsflow, else $HOME/.cache/capsflow, else "".
std::string resolve_cache_dir(const std::string& requested);

/// Load matrices whose key line equals `key`; false (and no change to mats' meaning) on any problem.
bool load_operator_cache(const std::string& path, const std::string& key,
                         std::vector<Eigen::MatrixXd>& mats);

/// Write atomically; creates the directory. Returns false if the file could not be written.
bool save_operator_cache(const std::string& path, const std::string& key,
                         const std::vector<Eigen::MatrixXd>& mats);

}  // namespace capsflow::fmm
