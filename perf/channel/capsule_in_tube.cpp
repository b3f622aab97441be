// capsule_in_tube — one capsule starting as a sphere on the axis of a tube, carried by Poiseuille's
// flow (V = 1, time in a/V), stepped by ChannelDynamics under error control in the frame that moves
// with its centroid (docs/channel.md §4). Prints a JSON line every --every of t (U/V, Δp⁺ two ways, the
// capsule's axial half-length and largest radial half-extent in units of a, the wall's GMRES
// iterations per evaluation) and a summary line.
//   capsule_in_tube --ratio 0.5 --level 2 --set flow.ca_s=0.01 --t-end 2 --threads 2
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/rhs/channel_dynamics.hpp"
#include "capsflow/core/stepping/time_plan.hpp"
#include "capsflow/core/stepping/time_stepper.hpp"

using namespace capsflow;

int main(int argc, char** argv) {
  CLI::App app{"a capsule on the axis of a tube in Poiseuille's flow"};
  int level = 2, threads = 0;
  double ratio = 0.5, per_radius = 8, lengths = 6, every = 0.1, t_end = 2, tolerance = 1e-5;
  std::vector<std::string> sets;
  app.add_option("--ratio", ratio, "capsule radius over tube radius, a/R");
  app.add_option("--level", level, "capsule mesh level (icosahedron)");
  app.add_option("--wall-per-radius", per_radius, "wall elements per tube radius");
  app.add_option("--length", lengths, "tube length in tube radii");
  app.add_option("--t-end", t_end, "end time in a/V");
  app.add_option("--every", every, "print every this much of t");
  app.add_option("--tolerance", tolerance, "RKC2 tolerance");
  app.add_option("--set", sets, "scene overrides (key=value), e.g. flow.ca_s=0.01");
  app.add_option("--threads", threads, "threads (0: OpenMP default)");
  CLI11_PARSE(app, argc, argv);

  std::vector<std::string> o = {fmt::format("mesh.level={}", level), "mesh.shape=\"sphere\"", "wall.model=\"membrane\"", "wall.law=\"skalak\"",
                                "time.scheme=\"rkc\""};
  o.insert(o.end(), sets.begin(), sets.end());
  const Scene s = parse_scene(default_scene_toml(), "capsule_in_tube", o);
  const SurfaceMesh ref = make_reference_mesh(s.mesh);
  ChannelFlow channel;
  channel.geometry.radius = 1 / ratio;
  channel.geometry.length = lengths / ratio;
  channel.geometry.element_size = 1 / ratio / per_radius;
  ChannelDynamics d(s, ref, channel, threads);
  Points x = ref.vertices;
  const TimePlan plan = resolve_time_plan(s, ref);
  auto stepper = make_time_stepper(s, plan, tolerance, ref.triangles, enclosed_volume(ref), x);
  double t = 0, next = every;
  long steps = 0;
  const auto start = std::chrono::steady_clock::now();
  auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  auto line = [&](const char* kind) {
    const Vec3 he = half_extents(SurfaceMesh{x, ref.triangles});
    nlohmann::json j = {{"kind", kind}, {"t", t}, {"steps", steps}, {"evaluations", d.counters().evaluations},
                        {"U_over_V", d.axial_velocity() / channel.mean_velocity}, {"pressure_drop", d.pressure_drop()},
                        {"pressure_drop_caps", d.pressure_drop_from_caps()}, {"half_length", he.x()},
                        {"radial_half_extent", std::max(he.y(), he.z())}, {"wall_gap", d.wall_gap()},
                        {"wall_gmres_per_evaluation", d.counters().evaluations ? double(d.wall_gmres_iterations()) / d.counters().evaluations : 0.0},
                        {"volume", enclosed_volume(SurfaceMesh{x, ref.triangles})}, {"seconds", seconds()}};
    std::puts(j.dump().c_str());
    std::fflush(stdout);
  };
  while (t < t_end - 1e-12) {
    const double dt = stepper->next_step(d, x, StepRequest{t, std::min(t_end, next) - t, steps});
    const StepAttempt a = stepper->attempt(d, x, dt);
    if (!a.accepted) continue;
    t += a.dt, ++steps;
    if (t >= next - 1e-12) line("progress"), next += every;
  }
  line("summary");
}
