// `capsflow info SCENE.toml`: the resolved scene and a report of the reference mesh.
#include <fmt/core.h>

#include <omp.h>

#include <cmath>

#include "capsflow/core/mesh/topology.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/geometry/taylor_deformation.hpp"
#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/stepping/stability.hpp"
#include "capsflow/core/driver/time_grid.hpp"
#include "capsflow/core/rhs/capsule_dynamics.hpp"
#include "capsflow/core/stepping/heun.hpp"
#include "capsflow/core/stepping/rkc.hpp"
#include "capsflow/core/phase_times.hpp"
#include "capsflow/core/scene/scene_keys.hpp"
#include "commands.hpp"

namespace capsflow::app {

int info_command(const InfoOptions& opt) {
  if (opt.keys) {  // the key table as docs/scene-and-output.md §2 has it, one section after the other
    std::string last;
    for (const SceneKeyDoc& k : scene_key_docs()) {
      if (k.section == last) continue;
      fmt::print("{}[{}]\n{}", last.empty() ? "" : "\n", k.section, scene_key_table(k.section));
      last = k.section;
    }
    return 0;
  }
  const Scene scene = opt.scene_path.empty() ? parse_scene(default_scene_toml(), "<built-in default>", opt.overrides)
                                             : load_scene(opt.scene_path, opt.overrides);
  fmt::print("# resolved scene ({})\n{}\n\n", scene.source, to_toml(scene));
  if (const std::string note = capillary_note(scene); !note.empty()) fmt::print("# note: {}\n\n", note);
  const SurfaceMesh mesh = make_reference_mesh(scene.mesh);
  const MeshStats st = mesh_stats(mesh);
  const VolumeMoments vm = volume_moments(mesh);
  const InertiaEllipsoid ell = inertia_ellipsoid(mesh);
  const TaylorDeformation D = taylor_deformation(ell);
  const Vec3 L = half_extents(mesh);
  fmt::print("# reference mesh\n");
  fmt::print("elements        {}\nnodes           {}\nedges           {}\n", st.elements, st.nodes, st.edges);
  fmt::print("edge length     min {:.4f}  mean {:.4f}  max {:.4f}\n", st.edge_min, st.edge_mean, st.edge_max);
  fmt::print("angles (deg)    min {:.2f}  max {:.2f}\n", st.min_angle_deg, st.max_angle_deg);
  std::string hist;
  for (const auto& [v, n] : st.valence_histogram) hist += fmt::format("{}:{} ", v, n);
  fmt::print("valence         {}\n", hist);
  fmt::print("volume          {:.6f}   (ℓ = {:.12f})\n", vm.volume, equivalent_radius(vm.volume));
  fmt::print("area            {:.6f}   (4πℓ² = {:.6f})\n", surface_area(mesh), 4 * M_PI * std::pow(equivalent_radius(vm.volume), 2));
  fmt::print("Le (inertia)    {:.4f} {:.4f} {:.4f}\n", ell.semi_axes[0], ell.semi_axes[1], ell.semi_axes[2]);
  fmt::print("L (extents)     {:.4f} {:.4f} {:.4f}\n", L[0], L[1], L[2]);
  fmt::print("D12 D13 D23     {:.4f} {:.4f} {:.4f}\n", D.D12, D.D13, D.D23);
  fmt::print("\n# run\n");
  std::string why;
  // The single layer's far-field sources are the edge midpoints (docs/boundary-integral.md §4.2.1).
  const FarFieldBackend b = choose_backend(scene.fluid.backend, mesh_edges(mesh).rows(), mesh.num_nodes(), scene.fluid.tolerance, &why);
  fmt::print("back end        {} ({})\n", to_string(b), why);
  if (const std::string note = unused_fmm_order_note(scene, b); !note.empty()) fmt::print("warning         {}\n", note);
  const StabilityEstimate se = stability_estimate(scene, st.edge_min);
  fmt::print("stable dt       {:.3e} at t = 0 for Heun (membrane {:.3e}, bending {:.3e}, flow cap {:.3e}; limited by {})\n",
             se.limit(), se.membrane, se.bending, se.flow, se.limiting());
  // Heun's real stability interval is 2, so the calibrated limit implies a spectral radius.
  const double rho_analytic = 2.0 / se.limit();
  double rho = rho_analytic, seconds_per_eval = NAN;
  double power_evaluations = 10;  // per ρ refresh, when not measured (--probe)
  const bool probe = opt.probe || mesh.num_elements() <= InfoOptions::kProbeElements;
  if (probe) {
    CapsuleDynamics dyn(scene, mesh);
    Points v;
    dyn.velocity(mesh.vertices, v);  // first call: rotation solve from the reference, FMM set-up
    Stopwatch clock;
    dyn.velocity(mesh.vertices, v);
    seconds_per_eval = clock.seconds();
    SpectralRadiusEstimator power;
    const SpectralRadiusEstimator::Result r = power.estimate(dyn, mesh.vertices, v);
    rho = kSpectralRadiusMargin * r.sigma;
    power_evaluations = r.evaluations;
    fmt::print("spectral radius {:.3e} by power iteration ({} evaluations{}; × {:g} margin), analytic {:.3e} (ratio {:.2f})\n",
               rho, r.evaluations, r.converged ? "" : ", NOT converged", kSpectralRadiusMargin, rho_analytic,
               rho / rho_analytic);
    fmt::print("evaluation      {:.3g} s per right-hand-side evaluation (measured, {} threads)\n", seconds_per_eval,
               omp_get_max_threads());
  } else {
    fmt::print("spectral radius {:.3e} analytic (from the calibrated Heun limit; --probe measures it)\n", rho_analytic);
  }
  auto wall = [&](double evals) {
    return std::isfinite(seconds_per_eval) ? fmt::format(", ~{:.0f} s", evals * seconds_per_eval) : std::string();
  };
  fmt::print("time scheme     {}{}\n", to_string(scene.time.scheme),
             !scene.time.scheme_auto ? "" : scene.time.scheme == TimeScheme::Rkc ? " (auto: a wall with bending stiffness)"
                                                                                 : " (auto: a membrane wall)");
  // Steps are shortened to land on every output time, so output.every < dt forces more steps.
  auto count = [](double steps) {
    return steps < 1e15 ? fmt::format("{:.0f}", steps)
                        : std::isfinite(steps) ? fmt::format("{:.3g}", steps) : std::string("more than 1e308");
  };
  // Every output evaluates the velocity at the state once more (the initial and the final one
  // included), and Heun refreshes ρ by power iteration every Heun::kRhoEvery steps from step 0.
  const double outputs = std::ceil(scene.time.t_end / scene.output.every - 1e-9) + 1;
  if (scene.time.scheme == TimeScheme::Heun) {
    // The run's automatic step also respects 2/ρ when the power iteration measured ρ.
    const double limit = probe ? std::min(se.limit(), 2.0 / rho) : se.limit();
    const double dt = scene.time.dt_auto ? scene.time.dt_safety * limit : scene.time.dt;
    const double steps = estimated_steps(scene.time.t_end, scene.output.every, dt);
    const double refreshes = std::floor(steps / static_cast<double>(Heun::kRhoEvery)) + 1;
    const double evals = 2 * steps + outputs + refreshes * power_evaluations;
    fmt::print("time step       {:.3e} ({}), about {} steps to t_end = {:g}: {} evaluations{} (2 per step, {:.0f} for the "
               "outputs, {:.0f} ρ refreshes × {:.0f}{})\n",
               dt, scene.time.dt_auto ? fmt::format("auto: {:g} × min(stable dt, 2/ρ), recomputed every step", scene.time.dt_safety) : "fixed",
               count(steps), scene.time.t_end, count(evals), wall(evals), outputs, refreshes, power_evaluations,
               probe ? "" : " assumed");
  } else if (!scene.time.dt_auto) {
    const double dt = scene.time.dt, steps = estimated_steps(scene.time.t_end, scene.output.every, dt);
    const int s = RkcCoefficients::stages_for(dt * rho);
    fmt::print("time step       {:.3e} (fixed): {} stages, about {} steps to t_end = {:g}: {} evaluations{}\n", dt, s,
               count(steps), scene.time.t_end, count(steps * s), wall(steps * s));
  } else {
    // The error-controlled step is not known in advance: the cost at typical steps.
    fmt::print("time step       error-controlled (tolerance {:g} ℓ); at a step of\n", scene.time.tolerance);
    for (double tau : {0.01, 0.03, 0.1}) {
      const int s = RkcCoefficients::stages_for(tau * rho);
      const double steps = estimated_steps(scene.time.t_end, scene.output.every, tau);
      fmt::print("  {:<6g}        {:>3} stages, {:.0f} evaluations to t_end = {:g}{}\n", tau, s, steps * s,
                 scene.time.t_end, wall(steps * s));
    }
  }
  // Measured peak RSS: ≈ 2.4 KB per element with the direct back end (48 MB at 20 480 elements);
  // the FMM operators add a fixed amount per order (≈ 0.46 GB at p = 9, measured).
  fmt::print("memory          ~{:.0f} MB{}\n", 2.4e-3 * static_cast<double>(mesh.num_elements()) + 15,
             b == FarFieldBackend::Fmm ? " + FMM operators (~0.5 GB at p = 9)" : "");
  return 0;
}

}  // namespace capsflow::app
