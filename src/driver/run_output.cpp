// What the run writes at output times (run.h5 step, profiles, a timeseries.csv row) and at
// checkpoints (docs/scene-and-output.md §3).
#include <fmt/core.h>

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/geometry/profiles.hpp"
#include "capsflow/core/io/checkpoint.hpp"
#include "capsflow/core/io/folder_lock.hpp"
#include "capsflow/core/io/manifest.hpp"
#include "capsflow/core/io/version.hpp"
#include "simulation_impl.hpp"

namespace capsflow {

namespace {
// Cross-sections in the three coordinate planes through the volume centroid, as the writer stores them.
std::vector<io::PlaneProfile> profiles_of(const SurfaceMesh& cur) {
  std::vector<io::PlaneProfile> planes;
  const Vec3 c = volume_moments(cur).centroid;
  for (CoordinatePlane p : {CoordinatePlane::X1X2, CoordinatePlane::X1X3, CoordinatePlane::X2X3}) {
    const auto lines = cross_section(cur, p, c);
    long n = 0;
    for (const auto& l : lines) n += static_cast<long>(l.points.size());
    io::PlaneProfile pr{to_string(p), Points(n, 3), Eigen::VectorXi(static_cast<Eigen::Index>(lines.size() + 1))};
    long k = 0;
    pr.offsets[0] = 0;
    for (size_t i = 0; i < lines.size(); ++i) {
      for (const auto& pt : lines[i].points) pr.points.row(k++) = pt.transpose();
      pr.offsets[static_cast<Eigen::Index>(i + 1)] = static_cast<int>(k);
    }
    planes.push_back(std::move(pr));
  }
  return planes;
}
}  // namespace

// Loads, energies and velocities of the state itself, not of whatever stage the scheme evaluated
// last: its F(x) when its last evaluation was here; otherwise evaluate.
const Points& Simulation::Impl::state_velocity() {
  if (const Points* v = stepper->velocity_at_state()) {
    v_out = *v;
  } else {
    dyn->evaluate(st.x, v_out, {EvaluationHint::Role::Output, 0});
    stepper->forget_state();  // the warm start moved: recompute F(x) (restart-safe)
  }
  return v_out;
}

void Simulation::Impl::update_far_checks() {
  far_check->update(dyn->single_layer(), st.t);
  if (const ViscosityRatioSolver* vr = dyn->viscosity_ratio_solver()) dl_far_check->update(vr->double_layer(), st.t);
}

void Simulation::Impl::write_output_at(double t, const Points& x, bool at_state) {
  folder_lock.check_held();  // a removed lock file: another writer may be here (io/folder_lock.hpp)
  const SurfaceMesh cur{x, ref.triangles};
  last_shape = shape_diagnostics(cur);
  const auto& s = last_shape;
  last_plane_shape = in_plane_shape(cur, plane);
  last_tank_treading = tank_treading->update(cur, t);
  // Between steps: what the right-hand side carries to the next step is put back on the way out.
  struct PutBack {
    CapsuleDynamics& dyn;
    std::optional<CapsuleDynamics::Carry> carry;
    ~PutBack() {
      if (carry) dyn.restore(std::move(*carry));
    }
  } put_back{*dyn, at_state ? std::nullopt : std::optional<CapsuleDynamics::Carry>(dyn->carry())};
  // Each may throw SolverFailure: the shapes above are the output state's all the same.
  if (at_state) {
    state_velocity();
    update_far_checks();
  } else if (scene.wants_field(OutputField::Velocity)) {
    dyn->evaluate(x, v_out, {EvaluationHint::Role::Output, 0});
  } else {
    dyn->solve_wall(x, {EvaluationHint::Role::Output, 0});  // loads and energies need no fluid
  }
  const shell::WallEnergies en = dyn->wall().energies(x);
  io::NamedFields fields;
  if (scene.wants_field(OutputField::Velocity)) fields.emplace_back("velocity", v_out);
  if (scene.wants_field(OutputField::Load)) fields.emplace_back("load", dyn->load());
  if (scene.wants_field(OutputField::Energy)) {
    Eigen::VectorXd Em, Eb, Esh;
    dyn->wall().nodal_energy_maps(x, Em, Eb, Esh);
    fields.emplace_back("E_membrane", Em);
    fields.emplace_back("E_bending", Eb);
    fields.emplace_back("E_shear", Esh);
  }
  out->write_step(t, x, fields);
  out->write_profiles(profiles_of(cur));
  const Vec3 centroid = lab_centroid_at(t, x);
  io::CsvRow row = {{"t", t}, {"step", static_cast<double>(st.step)}, {"dt", st.dt},
                    {"D12", s.D.D12}, {"D13", s.D.D13}, {"D23", s.D.D23},
                    {"Le1", s.Le[0]}, {"Le2", s.Le[1]}, {"Le3", s.Le[2]}, {"L1", s.L[0]}, {"L2", s.L[1]}, {"L3", s.L[2]},
                    {"area", s.area}, {"volume", s.volume}, {"volume_drift", s.volume / st.volume0 - 1},
                    {"centroid1", centroid[0]}, {"centroid2", centroid[1]}, {"centroid3", centroid[2]},
                    {"E_membrane", en.membrane}, {"E_bending", en.bending}, {"E_shear", en.shear},
                    {"steady_measure", steady->measure()}, {"wall_seconds", wall_seconds()}};
  for (const auto& [name, value] : health->columns()) row.emplace_back(name, value);
  far_check->append_columns(row);     // fluid.verify_every > 0 only
  dl_far_check->append_columns(row);  // ... and λ ≠ 1
  // In the flow plane (docs/conventions.md §5.6): θ in degrees, the rotation rate per unit γ̇t.
  row.insert(row.end(), {{"D_flow", last_plane_shape.D}, {"theta", last_plane_shape.theta * 180 / M_PI},
                         {"tank_treading", last_tank_treading}});
  if (dyn->viscosity_ratio_solver()) {  // λ ≠ 1: GMRES iterations per evaluation since the previous row
    const RhsCounters& n = dyn->counters();
    const long evals = n.evaluations - output_mark.evaluations;
    const double per_eval = evals > 0 ? static_cast<double>(n.gmres_iterations - output_mark.gmres_iterations) /
                                             static_cast<double>(evals)
                                       : std::numeric_limits<double>::quiet_NaN();
    row.emplace_back("gmres_per_eval", per_eval);
    if (per_eval > st.gmres_per_eval_max) st.gmres_per_eval_max = per_eval;
  }
  output_mark = dyn->counters();
  out->append_row(row);
  last_output_t = t;
}

void Simulation::Impl::write_checkpoint(const std::filesystem::path& path) {
  folder_lock.check_held();
  io::CheckpointState ck;
  ck.step = st.step;
  ck.t = st.t;
  ck.dt = st.dt;
  ck.positions = st.x;
  ck.reference_positions = ref.vertices;
  ck.triangles = ref.triangles;
  ck.wall_state = dyn->wall().state();
  ck.history = steady->history();
  ck.scene_toml = to_toml(scene);
  ck.scene_resolved = to_json(scene).dump();
  ck.version = fmt::format("{} ({})", version_string(), git_hash());
  RunState s = st;
  s.wall_seconds_before = wall_seconds();
  s.rhs_evaluations = rhs_evaluations();
  nlohmann::json extra = s.extra();
  extra["time_plan"] = plan.to_json();
  extra["health"] = health->state();
  stepper->save(extra, ck.integrator_state);
  dyn->save_fluid_state(extra, ck.fluid_state);
  if (far_check->enabled()) extra[far_check->name()] = far_check->state(dyn->single_layer());
  if (dl_far_check->enabled())
    extra[dl_far_check->name()] = dl_far_check->state(dyn->viscosity_ratio_solver()->double_layer());
  ck.extra = extra.dump();
  ck.run_id = run_id;
  io::write_checkpoint(path, ck);
}

// The run's own files are written by the run alone: a caller's checkpoint over run.h5 replaced it
// silently, and one named checkpoint.h5 pushed the run's own checkpoint into the previous slot.
// Another run's locked folder is that run's to write. Both refused with one line naming the path.
void Simulation::Impl::write_caller_checkpoint(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path target = fs::weakly_canonical(fs::absolute(path, ec), ec);  // through symbolic links
  const fs::path dir = target.parent_path();
  const fs::path own = fs::weakly_canonical(fs::absolute(folder, ec), ec);
  if (dir == own && io::is_run_folder_name(target.filename().string()))
    throw std::invalid_argument(fmt::format("checkpoint path '{}' is this run's own {} in {}: write the checkpoint under "
                                            "another name or in another folder",
                                            path.string(), target.filename().string(), folder.string()));
  if (dir != own)
    if (const auto holder = io::folder_held_by_another(dir))
      throw io::FolderBusy(fmt::format("checkpoint path '{}': its folder {} is in use by {}: one writer per folder (choose "
                                       "another folder)",
                                       path.string(), dir.string(), holder->describe()));
  write_checkpoint(path);
}

}  // namespace capsflow
