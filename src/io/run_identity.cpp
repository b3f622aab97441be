// Run identity (see run_identity.hpp).
#include "capsflow/core/io/run_identity.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <vector>

#include "capsflow/core/io/h5.hpp"
#include "capsflow/core/io/results_writer.hpp"
#include "capsflow/core/io/io_error.hpp"
#include "fnv1a.hpp"

namespace capsflow::io {
namespace fs = std::filesystem;

std::string new_run_id() {
  std::random_device rd;
  std::string id;
  for (int i = 0; i < 4; ++i) id += fmt::format("{:08x}", static_cast<std::uint32_t>(rd()));
  return id;
}

std::string mesh_hash(const Points& reference_positions, const Triangles& triangles) {
  detail::Fnv1a h;
  h.add_matrix(reference_positions);
  h.add_matrix(triangles);
  return h.hex();
}

FolderIdentity read_folder_identity(const fs::path& dir) {
  FolderIdentity id;
  const fs::path path = dir / kRunH5;
  std::error_code ec;
  if (!fs::exists(path, ec)) return id;
  id.has_run = true;
  try {
    const h5::File f = h5::File::open(path, h5::File::Mode::read_only, true);
    const h5::RowMatrixXd x0 = f.read_matrix<double>("mesh/reference_positions");
    const h5::RowMatrixXi tri = f.read_matrix<int>("mesh/triangles");
    if (x0.cols() != 3 || tri.cols() != 3) throw IoError("/mesh has unexpected shapes");
    id.mesh_hash = mesh_hash(Points(x0), Triangles(tri));
    if (f.exists("metadata/run_id")) {
      id.run_id = f.read_string("metadata/run_id");
    } else if (f.exists("metadata/restarts")) {
      // A folder from before run ids that was restarted since: the newest restart carries one.
      std::vector<std::string> names = f.open_group("metadata/restarts").children();
      std::sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) {
        return a.size() != b.size() ? a.size() < b.size() : a < b;
      });
      for (auto it = names.rbegin(); it != names.rend() && id.run_id.empty(); ++it)
        if (f.exists("metadata/restarts/" + *it + "/run_id")) id.run_id = f.read_string("metadata/restarts/" + *it + "/run_id");
    }
  } catch (const std::runtime_error& e) {
    throw IoError("cannot read the identity of the run in '" + dir.string() + "': " + e.what());
  }
  return id;
}

}  // namespace capsflow::io
