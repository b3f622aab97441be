// What a restart may do (see restart_rules.hpp).
#include "capsflow/core/driver/restart_rules.hpp"

#include <fmt/core.h>

#include <fstream>
#include <stdexcept>

#include "capsflow/core/driver/time_grid.hpp"
#include "capsflow/core/io/folder_lock.hpp"
#include "capsflow/core/io/results_writer.hpp"
#include "capsflow/core/io/run_identity.hpp"

namespace capsflow {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void refuse(const std::string& msg) { throw std::runtime_error(msg); }

std::string short_id(const std::string& id) { return id.empty() ? "(none)" : id.substr(0, 12); }

bool same_folder(const fs::path& a, const fs::path& b) {
  std::error_code ea, eb;
  const fs::path ca = fs::weakly_canonical(a, ea), cb = fs::weakly_canonical(b, eb);
  return !ea && !eb && ca == cb;
}

}  // namespace

void check_restart_overrides(const Scene& stored, const Scene& next, double t, long elements, bool finish_at_t_end) {
  const MeshSpec &a = stored.mesh, &b = next.mesh;
  const char* changed = a.file != b.file                ? "mesh.file"
                        : a.base != b.base              ? "mesh.base"
                        : a.level != b.level            ? "mesh.level"
                        : a.shape != b.shape            ? "mesh.shape"
                        : a.aspect != b.aspect          ? "mesh.aspect"
                        : a.axis != b.axis              ? "mesh.axis"
                                                        : nullptr;
  if (changed)
    refuse(fmt::format("--set {}: a restarted run keeps the mesh of its checkpoint ({} elements); start a new run to "
                       "change it", changed, elements));
  const LayoutSpec &la = stored.layout, &lb = next.layout;
  const char* moved = la.count != lb.count ? "layout.count"
                      : la.dx != lb.dx     ? "layout.dx"
                      : la.dy != lb.dy     ? "layout.dy"
                      : la.dz != lb.dz     ? "layout.dz"
                                           : nullptr;
  if (moved)
    refuse(fmt::format("--set {}: a restarted run keeps the capsules of its checkpoint where they are; start a new run to "
                       "place them otherwise", moved));
  if (stored.wall.model != next.wall.model)
    refuse(fmt::format("--set wall.model: the checkpoint holds the state of a {} wall; a restart cannot switch it to {} "
                       "(start a new run)", to_string(stored.wall.model), to_string(next.wall.model)));
  if (!(next.time.t_end > t) && !(finish_at_t_end && time_reached(t, next.time.t_end, 0.0)))
    refuse(fmt::format("time.t_end = {:g} is not after the checkpoint time t = {:g}: nothing to continue (give a later "
                       "--set time.t_end=...)", next.time.t_end, t));
}

std::int64_t restart_index(std::int64_t stored, double old_every, double new_every, double t) {
  return old_every == new_every ? stored : first_index_after(t, new_every);
}

fs::path checkpoint_folder(const fs::path& checkpoint_path) {
  return checkpoint_path.parent_path().empty() ? fs::path(".") : checkpoint_path.parent_path();
}

RestartPlan plan_restart(const io::CheckpointState& ck, const fs::path& checkpoint_path,
                         const std::vector<std::string>& overrides, const std::string& output_dir, bool finish_at_t_end) {
  RestartPlan plan;
  const std::string name = checkpoint_path.string() + " (scene)";
  const Scene stored = parse_scene(ck.scene_toml, name);
  plan.scene = parse_scene(ck.scene_toml, name, overrides);
  check_restart_overrides(stored, plan.scene, ck.t, static_cast<long>(ck.triangles.rows()), finish_at_t_end);

  const fs::path home = checkpoint_folder(checkpoint_path);
  plan.folder = output_dir.empty() ? home : fs::path(output_dir);
  const std::string q = "'" + plan.folder.string() + "'";
  std::error_code ec;
  const fs::file_status st = fs::status(plan.folder, ec);
  // The run's own lock file (taken before this plan) does not make a folder non-empty.
  if (!fs::exists(st) || (fs::is_directory(st) && io::is_empty_but_for_lock(plan.folder))) {
    plan.new_folder = true;
    plan.run_id = io::new_run_id();
    plan.parent_run_id = ck.run_id;
    return plan;
  }
  if (!fs::is_directory(st)) refuse("output path " + q + " exists and is not a folder");
  if ((stored.fluid.verify_every > 0) != (plan.scene.fluid.verify_every > 0))
    refuse("--set fluid.verify_every: switching the direct far-field check on or off changes the columns of " + q +
           "/timeseries.csv; continue into a new or empty folder with -o NEW");
  if ((stored.fluid.viscosity_ratio != 1.0) != (plan.scene.fluid.viscosity_ratio != 1.0))
    refuse("--set fluid.viscosity_ratio: switching between λ = 1 and λ ≠ 1 changes the columns of " + q +
           "/timeseries.csv (gmres_per_eval); continue into a new or empty folder with -o NEW");
  {  // a folder written before the flow-plane columns (D_flow, theta, tank_treading) cannot take today's rows
    std::ifstream csv(plan.folder / io::kTimeseriesCsv);
    std::string header;
    if (csv && std::getline(csv, header) && !header.empty() && ("," + header + ",").find(",theta,") == std::string::npos &&
        ("," + header + ",").find(",c1.theta,") == std::string::npos)
      refuse(q + "/timeseries.csv was written by an older capsflow, without the columns D_flow, theta and tank_treading; "
             "continue into a new or empty folder with -o NEW");
  }
  io::FolderIdentity id;
  try {
    id = io::read_folder_identity(plan.folder);
  } catch (const std::runtime_error& e) {
    refuse(std::string(e.what()) + "; continue into a new or empty folder with -o NEW");
  }
  if (!id.has_run)
    refuse("cannot continue in " + q + ": it is not empty and holds no run.h5 (not a capsflow run folder); continue "
           "into a new or empty folder with -o NEW");
  const std::string ck_mesh = io::mesh_hash(ck.reference_positions, ck.triangles);
  if (id.mesh_hash != ck_mesh)
    refuse(q + " belongs to another run (its mesh differs from the checkpoint's " + std::to_string(ck.triangles.rows()) +
           " elements); nothing was changed. Continue into a new or empty folder with -o NEW");
  if (!ck.run_id.empty() && !id.run_id.empty()) {
    if (ck.run_id != id.run_id)
      refuse(q + " belongs to another run (run id " + short_id(id.run_id) + "…, the checkpoint is from run " +
             short_id(ck.run_id) + "…); nothing was changed. Continue into a new or empty folder with -o NEW");
  } else if (!same_folder(plan.folder, home)) {
    refuse("cannot tell whether " + q + " belongs to the checkpoint's run (written before run ids); continue in the "
           "checkpoint's own folder, or into a new or empty folder with -o NEW");
  }
  plan.run_id = !ck.run_id.empty() ? ck.run_id : (!id.run_id.empty() ? id.run_id : io::new_run_id());
  return plan;
}

}  // namespace capsflow
