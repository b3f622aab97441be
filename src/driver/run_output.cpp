// What the run writes at output times (run.h5 step, profiles, a timeseries.csv row) and at
// checkpoints (docs/scene-and-output.md §3).
#include <fmt/core.h>

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/geometry/profiles.hpp"
#include "capsflow/core/geometry/rear_pole.hpp"
#include "capsflow/core/io/channel_wall_file.hpp"
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
// One capsule's shape, lab centroid and wall energies as timeseries.csv columns, names prefixed
// (one capsule: no prefix; several: "c<k>.").
void append_shape_columns(io::CsvRow& row, const std::string& p, const ShapeDiagnostics& s, double volume0, const Vec3& c,
                          const shell::WallEnergies& en) {
  row.insert(row.end(), {{p + "D12", s.D.D12}, {p + "D13", s.D.D13}, {p + "D23", s.D.D23},
                         {p + "Le1", s.Le[0]}, {p + "Le2", s.Le[1]}, {p + "Le3", s.Le[2]},
                         {p + "L1", s.L[0]}, {p + "L2", s.L[1]}, {p + "L3", s.L[2]},
                         {p + "area", s.area}, {p + "volume", s.volume}, {p + "volume_drift", s.volume / volume0 - 1},
                         {p + "centroid1", c[0]}, {p + "centroid2", c[1]}, {p + "centroid3", c[2]},
                         {p + "E_membrane", en.membrane}, {p + "E_bending", en.bending}, {p + "E_shear", en.shear}});
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

void Simulation::Impl::measure_shapes(const Points& x, double t) {
  for (int k = 0; k < capsules(); ++k) {
    CapsuleWatch& w = watch[static_cast<std::size_t>(k)];
    const SurfaceMesh cur = capsule_mesh(x, k);
    w.last_shape = shape_diagnostics(cur);
    w.last_plane_shape = in_plane_shape(cur, plane);
    w.last_tank_treading = w.tank_treading->update(cur, t);
  }
}

void Simulation::Impl::write_output_at(double t, const Points& x, bool at_state) {
  folder_lock.check_held();  // a removed lock file: another writer may be here (io/folder_lock.hpp)
  measure_shapes(x, t);
  // Between steps: what the right-hand side carries to the next step is put back on the way out.
  struct PutBack {
    CapsulesDynamics& dyn;
    std::optional<CapsulesDynamics::Carry> carry;
    ~PutBack() {
      if (carry) dyn.restore(std::move(*carry));
    }
  } put_back{*dyn, at_state ? std::nullopt : std::optional<CapsulesDynamics::Carry>(dyn->carry())};
  // Each may throw SolverFailure: the shapes above are the output state's all the same.
  if (at_state) {
    state_velocity();
    update_far_checks();
  } else if (scene.wants_field(OutputField::Velocity)) {
    dyn->evaluate(x, v_out, {EvaluationHint::Role::Output, 0});
  } else {
    dyn->solve_wall(x, {EvaluationHint::Role::Output, 0});  // loads and energies need no fluid
  }
  std::vector<shell::WallEnergies> en;
  for (int k = 0; k < capsules(); ++k)
    en.push_back(dyn->wall_of(k).energies(x.middleRows(surfaces->part(k).node_begin, surfaces->part(k).nodes)));
  io::NamedFields fields;
  if (scene.wants_field(OutputField::Velocity)) fields.emplace_back("velocity", v_out);
  if (scene.wants_field(OutputField::Load)) fields.emplace_back("load", dyn->load());
  if (scene.wants_field(OutputField::Energy)) {
    Eigen::VectorXd Em(x.rows()), Eb(x.rows()), Esh(x.rows()), em, eb, esh;
    for (int k = 0; k < capsules(); ++k) {  // each wall's maps on its capsule's rows
      const SurfacePart& p = surfaces->part(k);
      dyn->wall_of(k).nodal_energy_maps(x.middleRows(p.node_begin, p.nodes), em, eb, esh);
      Em.segment(p.node_begin, p.nodes) = em;
      Eb.segment(p.node_begin, p.nodes) = eb;
      Esh.segment(p.node_begin, p.nodes) = esh;
    }
    fields.emplace_back("E_membrane", Em);
    fields.emplace_back("E_bending", Eb);
    fields.emplace_back("E_shear", Esh);
  }
  out->write_step(t, x, fields);
  if (channel) io::write_channel_wall(folder, channel->channel_wall().mesh(), channel->channel_wall().traction(), t);
  std::vector<io::PlaneProfile> planes;
  for (int k = 0; k < capsules(); ++k)
    for (io::PlaneProfile& p : profiles_of(capsule_mesh(x, k))) {
      if (capsules() > 1) p.plane = fmt::format("capsule{}_{}", k + 1, p.plane);
      planes.push_back(std::move(p));
    }
  out->write_profiles(planes);
  const Vec3 centroid = lab_centroid_at(t, x);
  io::CsvRow row = {{"t", t}, {"step", static_cast<double>(st.step)}, {"dt", st.dt}};
  if (capsules() == 1) {
    append_shape_columns(row, "", watch[0].last_shape, st.volume0, centroid, en[0]);
    row.insert(row.end(), {{"steady_measure", steady->measure()}, {"wall_seconds", wall_seconds()}});
    for (const auto& [name, value] : watch[0].health->columns()) row.emplace_back(name, value);
    far_check->append_columns(row);     // fluid.verify_every > 0 only
    dl_far_check->append_columns(row);  // ... and λ ≠ 1
    // In the flow plane (docs/conventions.md §5.6): θ in degrees, the rotation rate per unit γ̇t.
    const CapsuleWatch& w = watch[0];
    row.insert(row.end(), {{"D_flow", w.last_plane_shape.D}, {"theta", w.last_plane_shape.theta * 180 / M_PI},
                           {"tank_treading", w.last_tank_treading}});
    if (channel)  // the capsule's speed over V, its added pressure drop, its rear's curvature, its closest approach to the wall
      row.insert(row.end(), {{"velocity_ratio", channel->axial_velocity() / channel->channel().mean_velocity},
                             {"pressure_drop", channel->pressure_drop()},
                             {"rear_curvature", rear_pole_curvature(x, ref.triangles)}, {"wall_gap", channel->wall_gap()}});
  } else {  // each capsule's columns prefixed "c<k>." (docs/several-capsules.md), then the run's
    const Vec3 common = volume_moments(x, ref.triangles).centroid;
    // The velocities at x, where this row evaluated them (the state's, or asked for by output.fields).
    const bool moving = at_state || scene.wants_field(OutputField::Velocity);
    for (int k = 0; k < capsules(); ++k) {
      CapsuleWatch& w = watch[static_cast<std::size_t>(k)];
      // Its velocity in the lab: the frame's L c̄_lab (geometry/lab_centroid.hpp) plus its own in the frame.
      const SurfacePart& part = surfaces->part(k);
      w.last_velocity = moving ? Vec3(scene.flow.gradient * centroid +
                                      centroid_rate(x.middleRows(part.node_begin, part.nodes), surfaces->local_triangles(k),
                                                    v_out.middleRows(part.node_begin, part.nodes)))
                               : Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
      const Vec3& u = w.last_velocity;
      const std::string p = fmt::format("c{}.", k + 1);
      append_shape_columns(row, p, w.last_shape, w.volume0, capsule_centroid_lab(centroid, common, x, k), en[k]);
      row.insert(row.end(), {{p + "velocity1", u[0]}, {p + "velocity2", u[1]}, {p + "velocity3", u[2]},
                             {p + "D_flow", w.last_plane_shape.D}, {p + "theta", w.last_plane_shape.theta * 180 / M_PI},
                             {p + "tank_treading", w.last_tank_treading}});
      for (const auto& [name, value] : w.health->columns()) row.emplace_back(p + name, value);
    }
    row.insert(row.end(), {{"volume_drift", enclosed_volume(SurfaceMesh{x, ref.triangles}) / st.volume0 - 1},
                           {"wall_seconds", wall_seconds()}});
    for (const auto& [name, value] : gap->columns()) row.emplace_back(name, value);
    far_check->append_columns(row);
  }
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
  ck.wall_state = wall_state();
  ck.history = steady->history();
  ck.scene_toml = to_toml(scene);
  ck.scene_resolved = to_json(scene).dump();
  ck.version = fmt::format("{} ({})", version_string(), git_hash());
  RunState s = st;
  s.wall_seconds_before = wall_seconds();
  s.rhs_evaluations = rhs_evaluations();
  nlohmann::json extra = s.extra();
  extra["time_plan"] = plan.to_json();
  if (capsules() == 1) {
    extra["health"] = watch[0].health->state();
  } else {
    extra["health"] = nlohmann::json::array();
    for (const CapsuleWatch& w : watch) extra["health"].push_back(w.health->state());
    extra["surface_gap"] = gap->state();
    extra["capsules"] = {{"nodes", nlohmann::json::array()}, {"elements", nlohmann::json::array()}};
    for (int k = 0; k < capsules(); ++k) {
      extra["capsules"]["nodes"].push_back(surfaces->part(k).nodes);
      extra["capsules"]["elements"].push_back(surfaces->part(k).elements);
    }
  }
  if (wall_gap) extra["wall_gap"] = wall_gap->state();
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
