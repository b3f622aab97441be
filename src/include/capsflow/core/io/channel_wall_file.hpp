#pragma once
// A channel's wall for ParaView (docs/channel.md §5): DIR/channel.h5 with /triangles (int32 M×3),
// /positions (float64 N×3) and /traction (float64 N×3, the wall's disturbance traction at the
// last output, attribute `time`), and DIR/channel.xmf, one grid over them ("XDMF Reader", as
// run.xmf). Both are replaced atomically at every output. The positions are in the run's frame,
// which moves with the capsule along the channel, as run.h5's positions are: opened together, the
// capsule sits in its channel.
#include <filesystem>

#include "capsflow/core/types.hpp"

namespace capsflow::io {

inline constexpr const char* kChannelH5 = "channel.h5";
inline constexpr const char* kChannelXdmf = "channel.xmf";

// Throws IoError for I/O failures, std::invalid_argument when traction does not have one row per node.
void write_channel_wall(const std::filesystem::path& folder, const SurfaceMesh& wall, const Points& traction, double t);

}  // namespace capsflow::io
