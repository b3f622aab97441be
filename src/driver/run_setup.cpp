// Everything before the first step (Simulation::set_up): the restart plan or the new scene, the
// output folder, the right-hand side, the scheme and the monitors, the state, the results writer.
#include <omp.h>
#include <spdlog/spdlog.h>

#include <fmt/core.h>

#include "capsflow/core/driver/capsule_placement.hpp"
#include "capsflow/core/driver/time_grid.hpp"
#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/geometry/taylor_deformation.hpp"
#include "capsflow/core/io/checkpoint.hpp"
#include "capsflow/core/io/folder_lock.hpp"
#include "capsflow/core/io/output_folder.hpp"
#include "capsflow/core/io/run_identity.hpp"
#include "capsflow/core/io/version.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/rhs/capsule_dynamics.hpp"
#include "capsflow/core/scene/boundary_integral_options.hpp"
#include "simulation_impl.hpp"

namespace capsflow {

void Simulation::Impl::set_up() {
  if (opt.threads > 0) omp_set_num_threads(opt.threads);
  threads = omp_get_max_threads();
  io::CheckpointState ck;
  set_up_folder(ck);
  choose_time_plan(ck);
  mesh_hash = io::mesh_hash(ref.vertices, ref.triangles);
  make_parts();
  stop_set_up_if_requested();  // the right-hand side's parts are most of the set-up; nothing written yet
  if (!opt.restart.empty()) restore(ck);
  else start_at_reference();
  const nlohmann::json meta = metadata();
  out = opt.restart.empty() || restart.new_folder ? new_results_writer()
                                                  : std::make_unique<io::ResultsWriter>(io::ResultsWriter::reopen(folder, st.t, meta));
  log_set_up();
  make_stepper();
  if (!opt.restart.empty()) {
    const auto e = nlohmann::json::parse(ck.extra);
    stepper->load(e, ck.integrator_state, st.x);
  }
  // The reference state: no episode of a wall's condition can begin here, but capsules may start
  // closer than contact.min_gap: a stop asked for it ends the run at its first step.
  if (opt.restart.empty())
    if (const std::optional<StopReason> r = observe_health()) stop(*r);
  effort_mark = dyn->counters();
  if (opt.restart.empty() || restart.new_folder) {
    write_first_output();
  } else {
    for (int k = 0; k < capsules(); ++k) {
      CapsuleWatch& w = watch[static_cast<std::size_t>(k)];
      const SurfaceMesh cur = capsule_mesh(st.x, k);
      w.last_shape = shape_diagnostics(cur);
      w.last_plane_shape = in_plane_shape(cur, plane);
      w.tank_treading->update(cur, st.t);  // the rate of the next row is measured from here
    }
  }
  t_segment_start = st.t;
}

// A new run resolves its plan on its mesh; a restart keeps the checkpoint's unless it changes a key
// the plan is made of (restart_keeps_time_plan), so that a continued run is stepped as it was.
void Simulation::Impl::choose_time_plan(const io::CheckpointState& ck) {
  if (!opt.restart.empty()) {
    const auto extra = nlohmann::json::parse(ck.extra);
    if (restart_keeps_time_plan(parse_scene(ck.scene_toml, "checkpoint"), scene)) {
      plan = TimePlan::from_json(extra.at("time_plan"));
      plan_from_checkpoint = true;
      return;
    }
  }
  plan = resolve_time_plan(scene, *surfaces);  // several capsules: the stiffest's
}

void Simulation::Impl::make_stepper() {
  stepper_tolerance = tolerance_in_force();
  if (capsules() == 1) {
    stepper = make_time_stepper(scene.capsule_scene(0), plan, stepper_tolerance, ref.triangles, st.volume0, st.x);
    return;
  }
  std::vector<double> volumes0;
  for (const CapsuleWatch& w : watch) volumes0.push_back(w.volume0);
  stepper = make_time_stepper(scene.capsule_scene(stiffest_capsule(scene, *surfaces)), plan, stepper_tolerance, *surfaces,
                              volumes0, st.x);
}

SurfaceMesh Simulation::Impl::capsule_mesh(const Points& x, int k) const {
  return capsules() == 1 ? SurfaceMesh{x, ref.triangles} : surfaces->part_mesh(x, k);
}

Vec3 Simulation::Impl::capsule_centroid_lab(const Vec3& common_lab, const Vec3& common_frame, const Points& x, int k) const {
  return common_lab + (volume_moments(capsule_mesh(x, k)).centroid - common_frame);
}

Eigen::VectorXd Simulation::Impl::wall_state() const {
  if (capsules() == 1) return dyn->wall_of(0).state();
  std::vector<Eigen::VectorXd> each;
  Eigen::Index n = 0;
  for (int k = 0; k < capsules(); ++k) n += each.emplace_back(dyn->wall_of(k).state()).size();
  Eigen::VectorXd all(n);
  n = 0;
  for (const Eigen::VectorXd& s : each) {
    all.segment(n, s.size()) = s;
    n += s.size();
  }
  return all;
}

void Simulation::Impl::set_wall_state(const Eigen::VectorXd& all) {
  if (capsules() == 1) return dyn->wall_of(0).set_state(all);
  Eigen::Index n = 0;
  for (int k = 0; k < capsules(); ++k) {
    const Eigen::Index size = dyn->wall_of(k).state().size();
    if (n + size > all.size()) throw std::runtime_error("checkpoint: the wall state is shorter than the capsules' walls");
    dyn->wall_of(k).set_state(all.segment(n, size));
    n += size;
  }
  if (n != all.size()) throw std::runtime_error("checkpoint: the wall state is longer than the capsules' walls");
}

void Simulation::Impl::make_parts() {
  steady = std::make_unique<SteadyStateDetector>(scene.time.steady_tol);
  suspension = nullptr;
  channel = nullptr;
  gap.reset();
  wall_gap.reset();
  if (scene.channel.active()) {
    auto in_channel = std::make_unique<ChannelDynamics>(scene.capsule_scene(0), ref, channel_flow_of(scene, ref), threads);
    channel = in_channel.get();
    wall_gap = std::make_unique<WallGapWatch>(scene.contact.min_gap);
    dyn = std::move(in_channel);
  } else if (capsules() == 1) {
    dyn = std::make_unique<CapsuleDynamics>(scene.capsule_scene(0), ref, threads);
  } else {
    auto several = std::make_unique<SuspensionDynamics>(
        scene, *surfaces, threads, ContactRepulsion{scene.contact.repulsion_range, scene.contact.repulsion_strength});
    suspension = several.get();
    dyn = std::move(several);
    std::vector<SurfacePart> parts;
    for (int k = 0; k < capsules(); ++k) parts.push_back(surfaces->part(k));
    gap = std::make_unique<SurfaceGapWatch>(scene.contact.min_gap, parts);
  }
  instability = InstabilityWatch(scene.fluid.volume_correction ? InstabilityWatch::Volume::Corrected
                                                               : InstabilityWatch::Volume::Uncorrected);
  far_check = std::make_unique<FarFieldWatch>(scene.fluid.verify_every, dyn->single_layer().far_field_tolerance());
  dl_far_check = std::make_unique<FarFieldWatch>(dyn->viscosity_ratio_solver() ? scene.fluid.verify_every : 0,
                                                 far_field_tolerance(scene).tolerance, "double_layer_far_field_check",
                                                 "double-layer far-field check", "the largest directly summed value");
  plane = flow_plane(scene.flow.gradient);
  watch.clear();
  for (int k = 0; k < capsules(); ++k) {
    CapsuleWatch& w = watch.emplace_back();
    const SurfaceMesh reference = capsule_mesh(ref.vertices, k);
    w.health = std::make_unique<HealthMonitor>(scene.capsule_scene(k), reference);
    w.tank_treading = std::make_unique<TankTreadingMeter>(plane);
    w.volume0 = enclosed_volume(reference);
  }
}

void Simulation::Impl::start_at_reference() {
  st.x = ref.vertices;
  st.volume0 = enclosed_volume(ref);
  st.centroid_frame = st.centroid_lab = volume_moments(ref).centroid;
  st.area0 = surface_area(ref);
  steady->add(0.0, st.area0, inertia_ellipsoid(ref));
}

void Simulation::Impl::write_first_output() {
  try {
    write_output();
  } catch (const SolverFailure& e) {  // the first evaluation failed: the run stops before its first step
    spdlog::error("{}", stop(StopReason(StopKind::SolverFailure, fmt::format("{} at t = {:g}", e.what(), st.t)))->to_string());
  }
  // A checkpoint as soon as the run starts: a run stopped by a full disk (or a file-size limit)
  // before its first periodic one still leaves a state to continue from.
  write_checkpoint(folder / io::kCheckpointFile);
}

namespace {

// The capsules of a checkpoint's union mesh: extra["capsules"] holds each one's node and element
// counts (absent: one capsule).
SurfaceSet stored_capsules(const SurfaceMesh& all, const nlohmann::json& extra) {
  if (!extra.contains("capsules")) return SurfaceSet({all});
  const auto nodes = extra.at("capsules").at("nodes").get<std::vector<Eigen::Index>>();
  const auto elements = extra.at("capsules").at("elements").get<std::vector<Eigen::Index>>();
  std::vector<SurfaceMesh> parts;
  Eigen::Index n0 = 0, e0 = 0;
  for (std::size_t k = 0; k < nodes.size() && k < elements.size(); ++k) {
    if (n0 + nodes[k] > all.num_nodes() || e0 + elements[k] > all.num_elements())
      throw std::runtime_error("checkpoint: its capsules' node and element counts exceed its mesh");
    SurfaceMesh m{all.vertices.middleRows(n0, nodes[k]), all.triangles.middleRows(e0, elements[k])};
    m.triangles.array() -= static_cast<int>(n0);
    parts.push_back(std::move(m));
    n0 += nodes[k];
    e0 += elements[k];
  }
  if (n0 != all.num_nodes() || e0 != all.num_elements())
    throw std::runtime_error("checkpoint: its capsules' node and element counts do not add up to its mesh");
  return SurfaceSet(parts);
}

// The folder a run will write: the new run's -o, or for a restart its -o or else the checkpoint's
// own folder (as plan_restart decides it, but known before the checkpoint is read).
std::filesystem::path folder_to_write(const RunOptions& opt) {
  namespace fs = std::filesystem;
  if (opt.restart.empty() || !opt.output_dir.empty()) return opt.output_dir;
  std::error_code ec;
  return fs::is_directory(opt.restart, ec) ? fs::path(opt.restart) : checkpoint_folder(opt.restart);
}

}  // namespace

void Simulation::Impl::set_up_folder(io::CheckpointState& ck) {
  namespace fs = std::filesystem;
  if (opt.restart.empty()) {  // a bad mesh or overlapping capsules are refused before any folder exists
    SurfaceSet set = place_capsules(opt.scene);
    check_capsules_apart(opt.scene, set);
    if (opt.scene.channel.active()) channel_flow_of(opt.scene, set.mesh());  // a capsule that does not fit is refused here
    ref = set.mesh();
    surfaces = std::make_unique<SurfaceSet>(std::move(set));
  }
  stop_set_up_if_requested();
  const fs::path target = folder_to_write(opt);
  if (target.empty()) throw io::IoError("the output folder path is empty");
  std::error_code ec;
  if (!opt.restart.empty() && !fs::exists(opt.restart, ec)) io::load_checkpoint_for_restart(opt.restart);  // throws: names it
  // One writer per folder: locked before any overwrite, identity or restart decision, and before a
  // restart reads a checkpoint that a running writer may still replace. A folder created only to
  // be locked is removed again when the set-up is refused.
  const bool existed = fs::exists(target, ec);
  folder_lock = io::FolderLock::acquire(target, "run");
  if (folder_lock.taken_over())
    spdlog::warn("output folder {}: {}", target.string(), folder_lock.taken_over()->takeover_note());
  try {
    if (opt.restart.empty()) set_up_new_folder();
    else set_up_restart_folder(ck);
    stop_set_up_if_requested();
  } catch (...) {
    folder_lock.release();
    if (!existed) fs::remove(target, ec);  // removes only a folder that is still empty
    throw;
  }
  folder_created = !existed;
}

void Simulation::Impl::stop_set_up_if_requested() {
  const int request = stop_request.load();
  if (request == 0) return;
  const bool locked = folder_lock.held();
  folder_lock.release();
  std::error_code ec;
  if (folder_created) std::filesystem::remove(folder, ec);  // removes only a folder that is still empty
  throw SetUpInterrupted(fmt::format("{} during the set-up: stopped before the first step{}",
                                     request > 0 ? fmt::format("signal {} received", request) : std::string("stop requested"),
                                     locked ? fmt::format(", nothing of this run written to {}", folder.string()) : std::string()));
}

void Simulation::Impl::set_up_restart_folder(io::CheckpointState& ck) {
  io::LoadedCheckpoint loaded = io::load_checkpoint_for_restart(opt.restart);
  if (!loaded.fallback_reason.empty())
    spdlog::warn("{}; continuing from the previous checkpoint {} (t = {:g})", loaded.fallback_reason, loaded.path.string(),
                 loaded.state.t);
  ck = std::move(loaded.state);
  checkpoint_path = loaded.path;
  restart = plan_restart(ck, loaded.path, opt.restart_overrides, opt.output_dir, opt.finish_at_t_end);  // refuses before any write
  scene = restart.scene;
  folder = restart.folder;
  if (restart.new_folder) io::prepare_output_folder(folder, false);
  else if (const auto removed = io::open_output_folder_for_restart(folder).removed; !removed.empty())
    spdlog::info("removed {} temporaries left by killed runs (first: {})", removed.size(), removed.front().filename().string());
  ref = SurfaceMesh{ck.reference_positions, ck.triangles};
  surfaces = std::make_unique<SurfaceSet>(stored_capsules(ref, nlohmann::json::parse(ck.extra)));
  run_id = restart.run_id;
}

void Simulation::Impl::set_up_new_folder() {
  scene = opt.scene;
  folder = opt.output_dir;
  const io::PreparedFolder prepared = io::prepare_output_folder(folder, opt.overwrite);
  if (!prepared.kept.empty())
    spdlog::info("output folder: kept {} entries capsflow did not write (first: {})", prepared.kept.size(),
                 prepared.kept.front().filename().string());
  run_id = io::new_run_id();
}

void Simulation::Impl::restore(const io::CheckpointState& ck) {
  st.x = ck.positions;
  st.t = ck.t;
  st.dt = ck.dt;
  st.step = ck.step;
  set_wall_state(ck.wall_state);
  steady->set_history(ck.history);
  const auto e = nlohmann::json::parse(ck.extra);
  st.set_extra(e);
  dyn->load_fluid_state(e, ck.fluid_state);  // the fluid solves' warm starts (λ ≠ 1, a channel's wall)
  if (e.contains(far_check->name())) far_check->set_state(e.at(far_check->name()));
  if (e.contains(dl_far_check->name())) dl_far_check->set_state(e.at(dl_far_check->name()));
  // A changed output.every or checkpoint_every counts its index from the checkpoint time.
  const Scene stored = parse_scene(ck.scene_toml, "checkpoint");
  st.next_output = restart_index(e.at("next_output").get<std::int64_t>(), stored.output.every, scene.output.every, st.t);
  st.next_checkpoint = restart_index(e.at("next_checkpoint").get<std::int64_t>(), stored.output.checkpoint_every,
                                     scene.output.checkpoint_every, st.t);
  if (e.contains("health")) {
    const nlohmann::json& h = e.at("health");  // one capsule: its monitor's state; several: a list
    for (int k = 0; k < capsules(); ++k) watch[static_cast<std::size_t>(k)].health->set_state(h.is_array() ? h.at(static_cast<std::size_t>(k)) : h);
  }
  if (gap && e.contains("surface_gap")) gap->set_state(e.at("surface_gap"));
  if (wall_gap && e.contains("wall_gap")) wall_gap->set_state(e.at("wall_gap"));
  last_output_t = st.t;
}

std::unique_ptr<io::ResultsWriter> Simulation::Impl::new_results_writer() const {
  io::MeshParts parts;
  if (capsules() > 1) {  // each capsule its grid in run.xmf
    parts.nodes.push_back(0);
    parts.elements.push_back(0);
    for (int k = 0; k < capsules(); ++k) {
      const SurfacePart& p = surfaces->part(k);
      parts.nodes.push_back(p.node_begin + p.nodes);
      parts.elements.push_back(p.element_begin + p.elements);
    }
  }
  return std::make_unique<io::ResultsWriter>(folder, ref, metadata(), std::move(parts));
}

nlohmann::json Simulation::Impl::metadata() const {
  nlohmann::json meta = {{"scene_toml", scene.toml_text}, {"scene_resolved", to_json(scene)},
                         {"command_line", opt.command_line}, {"version", version_string()},
                         {"git_hash", git_hash()}, {"build", build_info()}, {"threads", threads},
                         {"backend", to_string(dyn->single_layer().backend())},
                         {"backend_reason", dyn->single_layer().backend_reason()},
                         {"fmm_order", dyn->single_layer().fmm_order()},
                         {"fmm_leaf_size", dyn->single_layer().fmm_leaf_size()}};
  meta["run_id"] = run_id;
  meta["capsules"] = capsules();
  meta["mesh_hash"] = mesh_hash;
  if (st.rewind) meta["auto_tolerance_rewind"] = st.rewind->to_json();
  if (restart.new_folder) {
    meta["parent_run_id"] = restart.parent_run_id;
    meta["parent_checkpoint"] = std::filesystem::absolute(checkpoint_path).lexically_normal().string();
    meta["t_start"] = st.t;
  }
  return meta;
}

void Simulation::Impl::log_set_up() const {
  spdlog::info("capsflow {} (git {}), {} threads", version_string(), git_hash(), threads);
  spdlog::info("scene {}: {} elements, {} nodes, wall {} {}, flow {}, Ca_s = {:g}", scene.source, ref.num_elements(),
               ref.num_nodes(), to_string(scene.wall.model), shell::to_string(scene.wall.law), to_string(scene.flow.type),
               scene.flow.ca_s);
  if (capsules() > 1)
    spdlog::info("{} capsules, {} (docs/several-capsules.md), repulsion {}", capsules(),
                 scene.capsules_alike() ? fmt::format("{} elements each", surfaces->part(0).elements)
                                        : fmt::format("{} elements in all, some with keys of their own", ref.num_elements()),
                 scene.contact.repulsion_range > 0 ? fmt::format("within {:g} element sizes", scene.contact.repulsion_range)
                                                   : std::string("off"));
  spdlog::info("boundary integral: {} ({})", to_string(dyn->single_layer().backend()), dyn->single_layer().backend_reason());
  spdlog::info("output: {}{}", folder.string(), opt.restart.empty() ? "" : fmt::format(" (restart from t = {:g})", st.t));
  if (restart.new_folder) spdlog::info("new run folder from checkpoint {} (earlier history stays there)", checkpoint_path.string());
  if (out->run_file_rebuilt())
    spdlog::warn("run.h5 held a damaged object written after t = {:g} (the earlier run was killed while writing it): "
                 "run.h5 was rebuilt from the {} outputs up to the restart time",
                 st.t, out->num_steps());
  if (!opt.restart.empty() && time_reached(st.t, scene.time.t_end, 0.0))
    spdlog::info("the checkpoint is at time.t_end = {:g}: finishing the run (summary.json) without a step", scene.time.t_end);
  if (const std::string note = capillary_note(scene); !note.empty()) spdlog::info("note: {}", note);
  if (const std::string note = unused_fmm_order_note(scene, dyn->single_layer().backend()); !note.empty()) spdlog::warn("{}", note);
  spdlog::info("time scheme: {} ({}{}; docs/time-integration.md §5.2)", to_string(plan.scheme),
               plan_from_checkpoint ? "kept from the checkpoint: " : "", plan.reason);
}

}  // namespace capsflow
