// What `capsflow info` reports (info/scene_info.hpp): the numbers; src/app/info_command.cpp prints them.
#include "capsflow/core/info/scene_info.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/driver/capsule_placement.hpp"
#include "capsflow/core/driver/time_grid.hpp"
#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/geometry/taylor_deformation.hpp"
#include "capsflow/core/info/memory_estimate.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/mesh/topology.hpp"
#include "capsflow/core/phase_times.hpp"
#include "capsflow/core/rhs/capsule_dynamics.hpp"
#include "capsflow/core/rhs/channel_dynamics.hpp"
#include "capsflow/core/rhs/suspension_dynamics.hpp"
#include "capsflow/core/scene/boundary_integral_options.hpp"
#include "capsflow/core/stepping/heun.hpp"
#include "capsflow/core/stepping/rkc_coefficients.hpp"
#include "capsflow/core/stepping/rock4_coefficients.hpp"
#include "capsflow/core/stepping/stability.hpp"
#include "capsflow/core/stepping/time_plan.hpp"

namespace capsflow {

namespace {
// The stages of one RKC2 or ROCK4 step that spans τρ.
int stabilized_stages(TimeScheme scheme, double tau_rho) {
  return scheme == TimeScheme::Rock4 ? Rock4Coefficients::stages_for(tau_rho) : RkcCoefficients::stages_for(tau_rho);
}
}  // namespace

nlohmann::json scene_info(const Scene& scene, bool probe) {
  // Several capsules: the mesh section is capsule 1's, the run's counts are all capsules'.
  const SurfaceSet placed = place_capsules(scene);
  const SurfaceMesh mesh = placed.size() == 1 ? placed.mesh() : placed.part_mesh(placed.mesh().vertices, 0);
  const MeshStats st = mesh_stats(mesh);
  const TimePlan plan = resolve_time_plan(scene, placed);  // as the run will
  nlohmann::json info;
  info["source"] = scene.source;
  info["scene_toml"] = to_toml(scene);  // as given: "auto" stays "auto" (run.time_plan says what it chose)
  info["note"] = capillary_note(scene);

  const VolumeMoments vm = volume_moments(mesh);
  const InertiaEllipsoid ell = inertia_ellipsoid(mesh);
  const TaylorDeformation D = taylor_deformation(ell);
  const Vec3 L = half_extents(mesh);
  nlohmann::json valence = nlohmann::json::object();
  for (const auto& [v, n] : st.valence_histogram) valence[std::to_string(v)] = n;
  const double radius = equivalent_radius(vm.volume);
  info["mesh"] = {{"elements", st.elements}, {"nodes", st.nodes}, {"edges", st.edges},
                  {"edge_length", {{"min", st.edge_min}, {"mean", st.edge_mean}, {"max", st.edge_max}}},
                  {"angle_deg", {{"min", st.min_angle_deg}, {"max", st.max_angle_deg}}},
                  {"valence", valence},
                  {"volume", vm.volume}, {"equivalent_radius", radius},
                  {"area", surface_area(mesh)}, {"sphere_area", 4 * M_PI * std::pow(radius, 2)},
                  {"Le", {ell.semi_axes[0], ell.semi_axes[1], ell.semi_axes[2]}},
                  {"L", {L[0], L[1], L[2]}},
                  {"D12", D.D12}, {"D13", D.D13}, {"D23", D.D23}};

  nlohmann::json run;
  std::string why;
  // The single layer's far-field sources: the edge midpoints on flat facets, 3 Gauss points per
  // curved element (docs/boundary-integral.md §4.2.1).
  const SingleLayerOptions sl_options = boundary_integral_options(scene);
  // Several capsules: one far field over all of them (docs/several-capsules.md), K times the sources.
  const int capsules = placed.size();
  const SurfaceMesh& all = placed.mesh();
  const Eigen::Index all_edges = mesh_edges(all).rows();
  const Eigen::Index sources = far_field_source_count(sl_options, all.num_elements(), all_edges);
  const FarFieldBackend b = choose_backend(scene.fluid.backend, FarFieldKernel::SingleLayer, sources, all.num_nodes(),
                                           scene.fluid.tolerance, &why);
  if (capsules > 1)
    info["capsules"] = {{"count", capsules}, {"elements", all.num_elements()}, {"nodes", all.num_nodes()},
                        {"alike", scene.capsules_alike()}};
  std::optional<ChannelFlow> channel;
  if (scene.channel.active()) {  // docs/channel.md §5: the wall as the run builds it, and what one GMRES iteration costs
    channel = channel_flow_of(scene, mesh);
    const ChannelMesh wall = make_channel_mesh(channel->geometry);
    FixedWallOptions wo;
    wo.layer = sl_options;
    wo.layer.geometry = SurfaceGeometry::Flat;
    FixedWall fixed(wall.mesh, Points::Zero(wall.mesh.num_nodes(), 3), wo);
    const Points ones = Points::Ones(wall.mesh.num_nodes(), 3);
    Points u;
    fixed.apply(ones, u);  // the FMM's set-up, where the wall's far field sums by the FMM
    Stopwatch clock;
    fixed.apply(ones, u);
    info["channel"] = {{"shape", to_string(scene.channel.shape)}, {"radius", channel->geometry.radius},
                       {"length", channel->geometry.length}, {"element_size", channel->geometry.element_size},
                       {"element_size_auto", scene.channel.element_size_auto},
                       {"wall_nodes", wall.mesh.num_nodes()}, {"wall_elements", wall.mesh.num_elements()},
                       {"preconditioner_mb", fixed.preconditioner_megabytes()},
                       {"operator_mb", fixed.operator_megabytes()},
                       {"edge_pressure_mb", fixed.edge_pressure_megabytes()},
                       {"operator_dense", fixed.fixed_operator() && fixed.fixed_operator()->dense()},
                       {"seconds_per_wall_iteration", clock.seconds()}};
  }
  run["backend"] = to_string(b);
  run["backend_reason"] = why;
  const FarFieldTolerance tol = far_field_tolerance(scene);
  run["far_field_tolerance"] = {{"value", b == FarFieldBackend::Fmm ? tol.fmm_tolerance : tol.tolerance},
                                {"direct", tol.tolerance}, {"fmm", tol.fmm_tolerance}, {"reason", tol.reason}};
  run["fmm_order_warning"] = unused_fmm_order_note(scene, b);
  if (scene.fluid.viscosity_ratio != 1.0) {
    // The second-kind solve (docs/boundary-integral.md §4.8); its near-field lists depend on the geometry only.
    DoubleLayerOptions dl_options = double_layer_options(scene);
    dl_options.backend = BackendRequest::Direct;  // the near field's size only (no FMM set-up here)
    const DoubleLayerDiagnostics dl = DoubleLayer(mesh.triangles, mesh.num_nodes(), dl_options).diagnostics();
    std::string dl_why;  // the run's choice: by fluid.backend, or the stresslet FMM's crossover
    const FarFieldBackend dl_backend =
        choose_backend(scene.fluid.backend, FarFieldKernel::DoubleLayer, dl.far_field_sources, mesh.num_nodes(),
                       scene.fluid.tolerance, &dl_why);
    double_layer_set_up_direct(scene.fluid.backend, dl_backend, dl.far_field_sources, mesh.num_nodes(), scene.fluid.tolerance, &dl_why);
    const double lambda = scene.fluid.viscosity_ratio;
    run["viscosity_ratio"] = {{"lambda", lambda}, {"kappa", (1 - lambda) / (1 + lambda)},
                              {"near_field_mb", dl.near_field_megabytes}, {"max_gmres", scene.fluid.max_gmres},
                              {"double_layer_backend", to_string(dl_backend)}, {"double_layer_backend_reason", dl_why}};
  }
  // The stable step and ρ of the stiffest capsule (one capsule: its own).
  const int stiff = stiffest_capsule(scene, placed);
  const Scene own = scene.capsule_scene(stiff);
  const double edge_min = capsules == 1 ? st.edge_min : min_edge_length(placed.part_mesh(all.vertices, stiff));
  const StabilityEstimate se = stability_estimate(own, edge_min);
  run["stable_dt"] = {{"limit", se.limit()}, {"membrane", se.membrane}, {"bending", se.bending}, {"flow", se.flow},
                      {"limited_by", se.limiting()}};
  const double rho_analytic = analytic_spectral_radius(own, edge_min);
  double rho = rho_analytic, seconds_per_eval = NAN;
  double power_evaluations = 10;  // per ρ refresh, when not measured (--probe)
  const bool probed = probe || all.num_elements() <= kInfoProbeElements;
  nlohmann::json radius_info = {{"analytic", rho_analytic}, {"margin", kSpectralRadiusMargin}};
  if (probed) {
    // The run's right-hand side on the run's start: every capsule where the run places it.
    const Points& x0 = all.vertices;
    std::unique_ptr<CapsulesDynamics> rhs;
    if (channel) rhs = std::make_unique<ChannelDynamics>(scene.capsule_scene(0), mesh, *channel);
    else if (capsules == 1) rhs = std::make_unique<CapsuleDynamics>(scene.capsule_scene(0), mesh);
    else rhs = std::make_unique<SuspensionDynamics>(scene, placed, 0,
                                                    ContactRepulsion{scene.contact.repulsion_range, scene.contact.repulsion_strength});
    CapsulesDynamics& dyn = *rhs;
    Points v;
    dyn.evaluate(x0, v, {});  // first call: rotation solve from the reference, FMM set-up
    const long cold_iterations = dyn.counters().gmres_iterations;
    Stopwatch clock;
    dyn.evaluate(x0, v, {});
    seconds_per_eval = clock.seconds();
    if (channel)  // the reference shape has no load, so the wall took no iteration; a run's take about 10 (docs/channel.md §4)
      seconds_per_eval += 10 * info["channel"]["seconds_per_wall_iteration"].get<double>();
    if (const ViscosityRatioSolver* vr = dyn.viscosity_ratio_solver()) {
      // The repeated state needs no GMRES iteration; a run's evaluations take 1–3 (§4.8.3): count 2.
      const DoubleLayerDiagnostics dl = vr->double_layer().diagnostics();
      const double per_iteration = dl.apply_seconds / static_cast<double>(std::max(1L, dl.applications));
      seconds_per_eval += static_cast<double>(std::max(0L, 2 - (dyn.counters().gmres_iterations - cold_iterations))) * per_iteration;
      run["viscosity_ratio"]["setup_seconds"] = dl.setup_seconds / static_cast<double>(std::max(1L, dl.setups));
      run["viscosity_ratio"]["seconds_per_iteration"] = per_iteration;
      run["viscosity_ratio"]["cold_iterations"] = cold_iterations;
    }
    SpectralRadiusEstimator power;
    const SpectralRadiusEstimator::Result r = power.estimate(dyn, x0, v);
    rho = kSpectralRadiusMargin * r.sigma;
    power_evaluations = r.evaluations;
    radius_info["method"] = "power_iteration";
    radius_info["evaluations"] = r.evaluations;
    radius_info["converged"] = r.converged;
  } else {
    radius_info["method"] = "analytic";
  }
  radius_info["value"] = rho;
  run["spectral_radius"] = radius_info;
  run["seconds_per_evaluation"] = seconds_per_eval;
  run["threads"] = omp_get_max_threads();
  run["scheme"] = to_string(plan.scheme);
  run["time_plan"] = plan.to_json();
  // Heun's and fixed steps are shortened to land on every output time, so output.every < dt forces more steps.
  // Every output evaluates the velocity at the state once more (the initial and the final one
  // included), and Heun refreshes ρ by power iteration every Heun::kRhoEvery steps from step 0.
  const double outputs = std::ceil(scene.time.t_end / scene.output.every - 1e-9) + 1;
  if (plan.scheme == TimeScheme::Heun) {
    // The run's automatic step also respects 2/ρ when the power iteration measured ρ.
    const double limit = probed ? std::min(se.limit(), 2.0 / rho) : se.limit();
    const double dt = scene.time.dt_auto ? scene.time.dt_safety * limit : scene.time.dt;
    const double steps = estimated_steps(scene.time.t_end, scene.output.every, dt);
    const double refreshes = std::floor(steps / static_cast<double>(Heun::kRhoEvery)) + 1;
    run["time_step"] = {{"kind", "heun"}, {"dt", dt}, {"auto", scene.time.dt_auto}, {"dt_safety", scene.time.dt_safety},
                        {"steps", steps}, {"evaluations", 2 * steps + outputs + refreshes * power_evaluations},
                        {"output_evaluations", outputs}, {"rho_refreshes", refreshes},
                        {"evaluations_per_refresh", power_evaluations}, {"evaluations_per_refresh_assumed", !probed}};
  } else if (!plan.error_control) {
    const double dt = scene.time.dt, steps = estimated_steps(scene.time.t_end, scene.output.every, dt);
    const int s = stabilized_stages(plan.scheme, dt * rho);
    run["time_step"] = {{"kind", "fixed"}, {"dt", dt}, {"stages", s}, {"steps", steps}, {"evaluations", steps * s}};
  } else {
    // The error-controlled step is not known in advance: the cost at typical steps. Its steps land
    // on checkpoints and t_end only; outputs between steps are interpolated (dense output), and
    // cost an evaluation each only when they write velocities.
    nlohmann::json at = nlohmann::json::array();
    const double landing_every =
        scene.output.checkpoint_every > 0 ? std::min(scene.output.checkpoint_every, scene.time.t_end) : scene.time.t_end;
    const double output_evaluations = scene.wants_field(OutputField::Velocity) ? outputs : 0;
    for (double tau : {0.01, 0.03, 0.1}) {
      const int s = stabilized_stages(plan.scheme, tau * rho);
      const double steps = estimated_steps(scene.time.t_end, landing_every, tau);
      at.push_back({{"dt", tau}, {"stages", s}, {"evaluations", steps * s + output_evaluations}});
    }
    run["time_step"] = {{"kind", "error_controlled"},
                        {"tolerance", plan.tolerance},
                        {"at", at},
                        {"tolerance_auto", plan.tolerance_auto}};
    if (plan.at_creases == CreaseAction::Rewind) run["time_step"]["tolerance_folded"] = plan.crease_tolerance;
    if (plan.at_creases == CreaseAction::Loosen) run["time_step"]["tolerance_past_creases"] = plan.crease_tolerance;
  }
  run["time_step"]["t_end"] = scene.time.t_end;
  // The peak memory (info/memory_estimate.hpp), for the counts of all capsules together.
  const MemoryEstimate memory = estimate_peak_memory(scene, MeshCounts{all.num_elements(), all.num_nodes(), all_edges});
  // A channel adds its wall: 1.5 × its preconditioner (the near field and its LU factors, plus the
  // factorisation's work space) + 4 MB, fitted to the peak RSS of scenes/capsule_in_tube.toml for
  // 693, 2 762 and 5 169 wall nodes (17, 101 and 215 MB above the capsule alone: within 8 %), plus
  // the wall's operator where it is dense (up to 3 726 nodes). Measured with it (docs/channel.md
  // §5): 71, 652 and 232 MB against 70, 665 and 248 MB estimated; the sparse form's 35 MB at
  // 5 169 nodes did not show in the peak (237 MB before the operator was stored), so it is not counted;
  // plus the edges' pressure columns (docs/channel.md §3.5; a tube's are its rims', 6 MB at 2 762 nodes).
  double wall_mb = 0;
  if (channel) {
    const nlohmann::json& w = info["channel"];
    wall_mb = 1.5 * w["preconditioner_mb"].get<double>() + 4 + (w["operator_dense"].get<bool>() ? w["operator_mb"].get<double>() : 0.0) +
              w["edge_pressure_mb"].get<double>();
  }
  run["memory_mb"] = memory.total_mb() + wall_mb;
  run["memory_double_layer_mb"] = memory.double_layer_mb;
  info["run"] = run;
  return info;
}

}  // namespace capsflow
