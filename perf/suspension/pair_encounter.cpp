// pair_encounter — two capsules meeting in simple shear (v∞ = x2 e1), stepped by SuspensionDynamics
// under error control: capsule A starts at (−d, +δ/2, 0), B at (+d, −δ/2, 0), so that the shear
// brings them together, past each other and apart again. Stokes flow is reversible: rigid spheres
// end at the cross-stream offset δ they started with (Batchelor & Green 1972), and so does a pair
// of nearly rigid capsules; deformable ones end shifted. Prints a JSON line every --every of t
// (centroid offset Δx1, Δx2, the smallest gap in element sizes and in radii) and a summary line
// (initial and final Δx2, the smallest gap of the run, evaluations, seconds).
//   pair_encounter --level 2 --set wall.model=\"membrane\" --set wall.law=\"skalak\" --set flow.ca_s=0.005
//                  --offset 1.0 --half-distance 3 --threads 2        (one line)
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <omp.h>

#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/rhs/suspension_dynamics.hpp"
#include "capsflow/core/stepping/time_plan.hpp"
#include "capsflow/core/stepping/time_stepper.hpp"

using namespace capsflow;


int main(int argc, char** argv) {
  CLI::App app{"two capsules meeting in simple shear"};
  int level = 2, threads = 0;
  double offset = 1.0, half_distance = 3.0, every = 0.5, t_end = 0;
  ContactRepulsion contact;
  std::vector<std::string> sets;
  app.add_option("--level", level, "icosahedron level of each capsule");
  app.add_option("--offset", offset, "initial cross-stream offset δ of the centres (radii)");
  app.add_option("--half-distance", half_distance, "initial streamwise half-distance d (radii)");
  app.add_option("--t-end", t_end, "end time (0: 4d/δ, when the pair is as far apart as it started)");
  app.add_option("--every", every, "report interval of t");
  app.add_option("--repulsion-range", contact.range, "ContactRepulsion range in element sizes (0: off)");
  app.add_option("--repulsion-strength", contact.strength, "ContactRepulsion strength (flow units)");
  app.add_option("--set", sets, "scene keys, KEY=VALUE (as capsflow run --set)");
  app.add_option("--threads", threads, "OpenMP threads (0: all)");
  CLI11_PARSE(app, argc, argv);
  if (threads > 0) omp_set_num_threads(threads);
  if (t_end <= 0) t_end = 4 * half_distance / offset;
  std::vector<std::string> overrides = {fmt::format("mesh.level={}", level), "mesh.shape=\"sphere\"",
                                        "flow.type=\"simple_shear\"", "time.scheme=\"rkc\""};
  overrides.insert(overrides.end(), sets.begin(), sets.end());
  const Scene scene = parse_scene(default_scene_toml(), "pair_encounter", overrides);
  const SurfaceMesh ref = make_reference_mesh(scene.mesh);
  auto placed = [&](const Vec3& c) {
    SurfaceMesh m = ref;
    m.vertices.rowwise() += c.transpose();
    return m;
  };
  const SurfaceSet set({placed(Vec3(-half_distance, offset / 2, 0)), placed(Vec3(half_distance, -offset / 2, 0))});
  SuspensionDynamics f(scene, set, 0, contact);
  const TimePlan plan = resolve_time_plan(scene, ref);
  const double tolerance = plan.tolerance;
  const double v0 = enclosed_volume(ref);
  auto stepper = make_time_stepper(scene, plan, tolerance, set, {v0, v0}, set.mesh().vertices);
  Points x = set.mesh().vertices;
  double t = 0, next_report = every, min_gap = SurfaceGap::kNone, min_gap_distance = SurfaceGap::kNone;
  long steps = 0, rejected = 0, failures = 0;
  Points x_before;
  const auto start = std::chrono::steady_clock::now();
  auto offsets = [&] {
    return Vec3(volume_moments(set.part_mesh(x, 1)).centroid - volume_moments(set.part_mesh(x, 0)).centroid);
  };
  const Vec3 d0 = offsets();
  while (t < t_end * (1 - 1e-12)) {
    StepAttempt a;
    double dt = 0;
    try {
      x_before = x;
      dt = stepper->next_step(f, x, {t, std::min(t_end, next_report) - t, steps});
      a = stepper->attempt(f, x, dt);
    } catch (const SolverFailure& e) {  // as capsflow run: back to the state, a quarter of the step
      x = x_before;
      stepper->forget_state();
      if (dt == 0 || !stepper->shorten_after_failure(dt)) throw;
      ++failures;
      continue;
    }
    if (!a.accepted) {
      ++rejected;
      continue;
    }
    t += a.dt, ++steps;
    const SurfaceGap& g = f.layers().closest();
    if (g.ratio < min_gap) min_gap = g.ratio, min_gap_distance = g.distance;
    if (t >= next_report * (1 - 1e-12)) {
      const Vec3 d = offsets();
      fmt::print("{}\n", nlohmann::json{{"t", t}, {"dx1", d[0]}, {"dx2", d[1]}, {"gap_in_h", g.ratio},
                                        {"gap", g.distance}, {"steps", steps}}.dump());
      std::fflush(stdout);
      next_report += every;
    }
  }
  const Vec3 d = offsets();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print("{}\n", nlohmann::json{{"bench", "pair_encounter"},
                                    {"level", level},
                                    {"elements_per_capsule", ref.num_elements()},
                                    {"set", sets},
                                    {"repulsion", {contact.range, contact.strength}},
                                    {"scheme", to_string(plan.scheme)},
                                    {"tolerance", tolerance},
                                    {"t_end", t},
                                    {"dx2_start", -d0[1]},
                                    {"dx2_end", -d[1]},
                                    {"dx1_start", d0[0]},
                                    {"dx1_end", d[0]},
                                    {"net_shift", std::abs(d[1]) - std::abs(d0[1])},
                                    {"min_gap_in_h", min_gap},
                                    {"min_gap", min_gap_distance},
                                    {"steps", steps},
                                    {"rejected", rejected},
                                    {"failed_attempts", failures},
                                    {"evaluations", f.counters().evaluations},
                                    {"seconds", seconds},
                                    {"threads", omp_get_max_threads()}}
                         .dump());
  return 0;
}
