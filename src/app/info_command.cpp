// `capsflow info SCENE.toml`: the resolved scene and a report of the reference mesh and the run
// ahead, printed from scene_info (info/scene_info.hpp), which Python's Scene.info() returns.
#include <fmt/core.h>

#include <cmath>
#include <map>
#include <string>

#include "capsflow/core/info/scene_info.hpp"
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
  const nlohmann::json info = scene_info(scene, opt.probe);  // resolves "auto" against the mesh, as a run does
  fmt::print("# resolved scene ({})\n{}\n\n", scene.source, info["scene_toml"].get<std::string>());
  if (const std::string note = capillary_note(scene); !note.empty()) fmt::print("# note: {}\n\n", note);
  const nlohmann::json& m = info["mesh"];
  auto num = [](const nlohmann::json& j) { return j.get<double>(); };
  fmt::print("# reference mesh\n");
  fmt::print("elements        {}\nnodes           {}\nedges           {}\n", m["elements"].get<long>(), m["nodes"].get<long>(),
             m["edges"].get<long>());
  fmt::print("edge length     min {:.4f}  mean {:.4f}  max {:.4f}\n", num(m["edge_length"]["min"]), num(m["edge_length"]["mean"]),
             num(m["edge_length"]["max"]));
  fmt::print("angles (deg)    min {:.2f}  max {:.2f}\n", num(m["angle_deg"]["min"]), num(m["angle_deg"]["max"]));
  std::map<int, long> valences;  // in numeric order, as mesh_stats lists them
  for (const auto& [v, n] : m["valence"].items()) valences[std::stoi(v)] = n.get<long>();
  std::string hist;
  for (const auto& [v, n] : valences) hist += fmt::format("{}:{} ", v, n);
  fmt::print("valence         {}\n", hist);
  fmt::print("volume          {:.6f}   (ℓ = {:.12f})\n", num(m["volume"]), num(m["equivalent_radius"]));
  fmt::print("area            {:.6f}   (4πℓ² = {:.6f})\n", num(m["area"]), num(m["sphere_area"]));
  fmt::print("Le (inertia)    {:.4f} {:.4f} {:.4f}\n", num(m["Le"][0]), num(m["Le"][1]), num(m["Le"][2]));
  fmt::print("L (extents)     {:.4f} {:.4f} {:.4f}\n", num(m["L"][0]), num(m["L"][1]), num(m["L"][2]));
  fmt::print("D12 D13 D23     {:.4f} {:.4f} {:.4f}\n", num(m["D12"]), num(m["D13"]), num(m["D23"]));
  if (info.contains("capsules"))
    fmt::print("capsules        {}{}: {} elements, {} nodes in all (docs/several-capsules.md)\n",
               info["capsules"]["count"].get<long>(),
               info["capsules"]["alike"].get<bool>() ? " of this mesh" : " (the mesh above is capsule 1's; some have keys of their own)",
               info["capsules"]["elements"].get<long>(), info["capsules"]["nodes"].get<long>());
  if (info.contains("channel")) {
    const nlohmann::json& c = info["channel"];
    fmt::print("channel         {} of radius {:g} and length {:g}; wall of {} elements, {} nodes (element size {:.4g}{}); its "
               "solve: GMRES preconditioned by its near field ({:.1f} MB), its operator set up once ({}, {:.1f} MB; "
               "the edges' pressure {:.1f} MB), {:.3g} s per iteration, about 10 per evaluation (docs/channel.md)\n",
               c["shape"].get<std::string>(), c["radius"].get<double>(), c["length"].get<double>(),
               c["wall_elements"].get<long>(), c["wall_nodes"].get<long>(), c["element_size"].get<double>(),
               c["element_size_auto"].get<bool>() ? ", auto" : "", c["preconditioner_mb"].get<double>(),
               c["operator_dense"].get<bool>() ? "dense" : "sparse near field", c["operator_mb"].get<double>(),
               c["edge_pressure_mb"].get<double>(), c["seconds_per_wall_iteration"].get<double>());
  }
  fmt::print("\n# run\n");
  const nlohmann::json& r = info["run"];
  fmt::print("back end        {} ({})\n", r["backend"].get<std::string>(), r["backend_reason"].get<std::string>());
  fmt::print("far field       accurate to {:g} of max |v| (fluid.tolerance {})\n", num(r["far_field_tolerance"]["value"]),
             r["far_field_tolerance"]["reason"].get<std::string>());
  if (const std::string note = r["fmm_order_warning"]; !note.empty()) fmt::print("warning         {}\n", note);
  if (r.contains("viscosity_ratio")) {
    const nlohmann::json& vr = r["viscosity_ratio"];
    fmt::print("viscosity ratio λ = {:g}: (1 + λ)/2 u + (1 − λ) D[u] = v∞ − S[q] at every evaluation, the double layer "
               "weighted by (1 − λ)/(1 + λ) = {:.4g}; deflated GMRES to fluid.tolerance, warm-started "
               "(docs/boundary-integral.md §4.8)\n",
               num(vr["lambda"]), num(vr["kappa"]));
    fmt::print("  cost          per evaluation: the single layer, one double-layer set-up (a far-field pass and the "
               "near-field blocks, {:.0f} MB) and GMRES iterations (1–3 warm-started, ≤ 10 cold, at most "
               "fluid.max_gmres = {}; docs/boundary-integral.md §4.8.3) of one double-layer far-field sum and one "
               "sparse product each\n",
               num(vr["near_field_mb"]), vr["max_gmres"].get<int>());
    fmt::print("  double layer  far field: {} ({}); a direct sum costs O(N²) per GMRES iteration, the FMM O(N)\n",
               vr["double_layer_backend"].get<std::string>(), vr["double_layer_backend_reason"].get<std::string>());
  }
  const nlohmann::json& se = r["stable_dt"];
  fmt::print("stable dt       {:.3e} at t = 0 for Heun (membrane {:.3e}, bending {:.3e}, flow cap {:.3e}; limited by {})\n",
             num(se["limit"]), num(se["membrane"]), num(se["bending"]), num(se["flow"]), se["limited_by"].get<std::string>());
  const nlohmann::json& rho = r["spectral_radius"];
  if (rho["method"] == "power_iteration") {
    fmt::print("spectral radius {:.3e} by power iteration ({} evaluations{}; × {:g} margin), analytic {:.3e} (ratio {:.2f})\n",
               num(rho["value"]), rho["evaluations"].get<long>(), rho["converged"].get<bool>() ? "" : ", NOT converged",
               num(rho["margin"]), num(rho["analytic"]), num(rho["value"]) / num(rho["analytic"]));
    const bool second_kind = r.contains("viscosity_ratio");
    fmt::print("evaluation      {:.3g} s per right-hand-side evaluation (measured, {} threads{})\n", num(r["seconds_per_evaluation"]),
               r["threads"].get<int>(), second_kind ? "; with 2 GMRES iterations" : "");
    if (second_kind)
      fmt::print("double layer    set-up {:.3g} s, {:.3g} s per GMRES iteration; the first, cold solve took {} iterations\n",
                 num(r["viscosity_ratio"]["setup_seconds"]), num(r["viscosity_ratio"]["seconds_per_iteration"]),
                 r["viscosity_ratio"]["cold_iterations"].get<long>());
  } else {
    fmt::print("spectral radius {:.3e} analytic (from the calibrated Heun limit; --probe measures it)\n", num(rho["analytic"]));
  }
  const double seconds_per_eval = num(r["seconds_per_evaluation"]);
  auto wall = [&](double evals) {
    return std::isfinite(seconds_per_eval) ? fmt::format(", ~{:.0f} s", evals * seconds_per_eval) : std::string();
  };
  fmt::print("time scheme     {} ({}; docs/time-integration.md §5.2)\n", r["scheme"].get<std::string>(),
             r["time_plan"]["reason"].get<std::string>());
  auto count = [](double steps) {
    return steps < 1e15 ? fmt::format("{:.0f}", steps)
                        : std::isfinite(steps) ? fmt::format("{:.3g}", steps) : std::string("more than 1e308");
  };
  const nlohmann::json& ts = r["time_step"];
  const double t_end = num(ts["t_end"]);
  if (ts["kind"] == "heun") {
    const double evals = num(ts["evaluations"]);
    fmt::print("time step       {:.3e} ({}), about {} steps to t_end = {:g}: {} evaluations{} (2 per step, {:.0f} for the "
               "outputs, {:.0f} ρ refreshes × {:.0f}{})\n",
               num(ts["dt"]),
               ts["auto"].get<bool>() ? fmt::format("auto: {:g} × min(stable dt, 2/ρ), recomputed every step", num(ts["dt_safety"]))
                                      : "fixed",
               count(num(ts["steps"])), t_end, count(evals), wall(evals), num(ts["output_evaluations"]), num(ts["rho_refreshes"]),
               num(ts["evaluations_per_refresh"]), ts["evaluations_per_refresh_assumed"].get<bool>() ? " assumed" : "");
  } else if (ts["kind"] == "fixed") {
    fmt::print("time step       {:.3e} (fixed): {} stages, about {} steps to t_end = {:g}: {} evaluations{}\n", num(ts["dt"]),
               ts["stages"].get<int>(), count(num(ts["steps"])), t_end, count(num(ts["evaluations"])), wall(num(ts["evaluations"])));
  } else {
    if (ts["tolerance_auto"].get<bool>() && ts.contains("tolerance_folded"))
      fmt::print("time step       error-controlled (tolerance auto: {:g} ℓ; if the wall creases at the mesh scale, the run starts "
                 "again from t = 0 at {:g} ℓ up to the creases); at a step of\n",
                 num(ts["tolerance"]), num(ts["tolerance_folded"]));
    else if (ts.contains("tolerance_past_creases") && num(ts["tolerance_past_creases"]) != num(ts["tolerance"]))
      fmt::print("time step       error-controlled (tolerance auto: {:g} ℓ; {:g} ℓ from where the wall creases at the mesh "
                 "scale); at a step of\n",
                 num(ts["tolerance"]), num(ts["tolerance_past_creases"]));
    else
      fmt::print("time step       error-controlled (tolerance {}{:g} ℓ); at a step of\n",
                 ts["tolerance_auto"].get<bool>() ? "auto: " : "", num(ts["tolerance"]));
    for (const nlohmann::json& at : ts["at"])
      fmt::print("  {:<6g}        {:>3} stages, {:.0f} evaluations to t_end = {:g}{}\n", num(at["dt"]), at["stages"].get<int>(),
                 num(at["evaluations"]), t_end, wall(num(at["evaluations"])));
  }
  const double dl_mb = num(r["memory_double_layer_mb"]);
  fmt::print("memory          ~{:.0f} MB at the peak{} (2 threads; docs/scene-and-output.md §1.2)\n", num(r["memory_mb"]),
             dl_mb > 0 ? fmt::format(", of which the double layer {:.0f} MB", dl_mb) : std::string());
  return 0;
}

}  // namespace capsflow::app
