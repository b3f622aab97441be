#pragma once
// What `capsflow info` reports about a scene, as data (capsflow info prints it; Python's
// Scene.info() returns it as a dict; docs/scene-and-output.md §1, docs/python.md §3): the
// resolved scene, the reference mesh (counts, edge lengths, angles, valences, volume, area,
// extents, deformation), and the run ahead (far-field back end, stable time step, spectral radius,
// time scheme and step, cost estimate, memory).
//
// Keys (numbers are plain doubles or integers; an infinite limit stays infinite):
//   source, scene_toml, note ("" or the Ca_s note)
//   mesh: elements, nodes, edges, edge_length {min, mean, max}, angle_deg {min, max},
//         valence {"5": nodes, ...}, volume, equivalent_radius, area, sphere_area (4πℓ²),
//         Le [3] (inertia ellipsoid), L [3] (extents), D12, D13, D23
//   run: backend, backend_reason, fmm_order_warning ("" or the note), stable_dt {limit, membrane,
//        bending, flow, limited_by}, spectral_radius {value, method ("power_iteration" |
//        "analytic"), analytic, evaluations, converged, margin}, seconds_per_evaluation (NaN when
//        not probed), threads, scheme, time_plan (stepping/time_plan.hpp), time_step {kind, t_end and — heun: dt, auto,
//        dt_safety, steps, evaluations (2 per step + output_evaluations + rho_refreshes ×
//        evaluations_per_refresh, _assumed when not measured); fixed (RKC): dt, stages, steps,
//        evaluations; error_controlled (RKC): tolerance, at [{dt, stages, evaluations}]},
//        memory_mb, memory_double_layer_mb (info/memory_estimate.hpp)
#include <nlohmann/json.hpp>

#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

// The right-hand side is evaluated (time per evaluation, spectral radius by power iteration) when
// `probe` or the mesh has at most kInfoProbeElements elements.
inline constexpr long kInfoProbeElements = 20480;

nlohmann::json scene_info(const Scene& scene, bool probe);

}  // namespace capsflow
