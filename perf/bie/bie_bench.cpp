// bie_bench — time and accuracy of one single-layer evaluation on the unit icosphere, per level,
// back end and surface geometry. Accuracy oracles (μ = 1, a = 1): a uniform load c gives the
// rigid velocity 2c/3 (timed case; error max_i |u_i − 2c/3| / |2c/3|); the load ω × n gives the
// rotation ω × x/3 (error relative to |ω|/3); a uniform normal load gives 0 (relative to 2/3).
// One JSON line per (level, geometry, backend, tolerance).
//   bie_bench --levels 3,4,5,6 --backends direct,fmm --geometry flat,curved --tol 1e-6 --repeat 5 --threads 2
// The FMM/direct crossover of backend "auto": perf/bie/crossover.sh.
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/io/version.hpp"

using namespace capsflow;

int main(int argc, char** argv) {
  CLI::App app{"single-layer evaluation benchmark"};
  std::vector<int> levels{3, 4, 5};
  std::vector<std::string> backends{"direct", "fmm"};
  std::vector<double> tols{1e-6};
  std::vector<std::string> geometries{"flat"};
  std::vector<std::string> bases{"icosahedron"};
  std::string far_rule = "auto";
  int repeat = 5, threads = 0, ring_depth = 0, ring_layers = 0, corrected_layers = 0;
  bool uniform_only = false, direct_per_tol = false;
  const SingleLayerOptions defaults;
  int nv = defaults.singular_points, nu = defaults.singular_radial_points;
  app.add_option("--levels", levels, "icosahedron levels")->delimiter(',');
  app.add_option("--backends", backends, "direct,fmm")->delimiter(',');
  app.add_option("--geometry", geometries, "flat,curved")->delimiter(',');
  app.add_option("--tol", tols, "FMM tolerances")->delimiter(',');
  app.add_option("--near-ring-depth", ring_depth, "near ring: 7-point rule on 4^depth parts (-1: no ring)");
  app.add_option("--near-ring-layers", ring_layers, "edge hops of the near ring beyond the touching elements (0: auto)");
  app.add_option("--corrected-layers", corrected_layers, "edge hops within which the midpoint far field is replaced (0: auto)");
  app.add_option("--far-rule", far_rule, "auto, midpoints or gauss: the far field's element rule");
  app.add_option("--base", bases, "icosahedron,octahedron: the solid the sphere is subdivided from")->delimiter(',');
  app.add_flag("--direct-per-tol", direct_per_tol, "time the direct back end at every tolerance (single-precision pairs from 1e-5)");
  app.add_option("--singular-points", nv, "curvature correction: Gauss points in v per side");
  app.add_option("--singular-radial-points", nu, "curvature correction: Gauss points in u");
  app.add_flag("--uniform-only", uniform_only, "skip the rotation and normal-load errors (two evaluations)");
  app.add_option("--repeat", repeat, "timed evaluations (median reported)");
  app.add_option("--threads", threads, "OpenMP threads");
  CLI11_PARSE(app, argc, argv);
  if (threads > 0) omp_set_num_threads(threads);
  const Vec3 c(0.3, -1.0, 0.5), omega(0.2, 0.7, -0.4);
  for (const auto& base : bases)
  for (int level : levels) {
    const SurfaceMesh m = make_sphere_mesh(from_string<BaseSolid>(base).value(), level);
    Points q(m.num_nodes(), 3), q_rot(m.num_nodes(), 3), rot(m.num_nodes(), 3);
    q.rowwise() = c.transpose();
    for (Eigen::Index i = 0; i < m.num_nodes(); ++i) {
      const Vec3 x = m.vertices.row(i).transpose();
      q_rot.row(i) = omega.cross(x).transpose();
      rot.row(i) = (omega.cross(x) / 3.0).transpose();
    }
    for (const auto& geometry : geometries)
    for (const auto& b : backends)
      for (double tol : tols) {
        if (b == "direct" && !direct_per_tol && tol != tols.front()) continue;
        SingleLayerOptions o;
        o.backend = from_string<BackendRequest>(b).value();
        o.tolerance = tol;
        o.geometry = from_string<SurfaceGeometry>(geometry).value();
        o.near_ring_depth = ring_depth;
        o.near_ring_layers = ring_layers;
        o.corrected_layers = corrected_layers;
        o.far_rule = far_rule == "midpoints" ? FarFieldRule::EdgeMidpoints
                     : far_rule == "gauss"   ? FarFieldRule::GaussPoints
                                             : FarFieldRule::Auto;
        o.singular_points = nv;
        o.singular_radial_points = nu;
        const auto t_setup = std::chrono::steady_clock::now();
        SingleLayer S(m.triangles, m.num_nodes(), o);
        const double construct_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_setup).count();
        Points u;
        if (b == "fmm") S.apply(m.vertices, q, u);  // warm-up (FMM operator cache, first touch)
        std::vector<double> times;
        const PhaseTimes before = S.times();
        for (int r = 0; r < repeat; ++r) {
          const auto t0 = std::chrono::steady_clock::now();
          S.apply(m.vertices, q, u);
          times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        }
        const PhaseTimes after = S.times();
        std::sort(times.begin(), times.end());
        const double err = (u.rowwise() - (2.0 / 3.0) * c.transpose()).rowwise().norm().maxCoeff() / ((2.0 / 3.0) * c.norm());
        double err_rot = NAN, err_nrm = NAN;
        if (!uniform_only) {
          S.apply(m.vertices, q_rot, u);
          err_rot = (u - rot).rowwise().norm().maxCoeff() / (omega.norm() / 3.0);
          S.apply(m.vertices, m.vertices, u);  // unit sphere: n = x
          err_nrm = u.rowwise().norm().maxCoeff() / (2.0 / 3.0);
        }
        nlohmann::json j = {{"what", "single_layer"}, {"level", level}, {"elements", m.num_elements()}, {"nodes", m.num_nodes()},
                            {"base", base}, {"sources", S.far_field_sources()}, {"backend", b}, {"tol", b == "fmm" || direct_per_tol ? tol : 0.0},
                            {"order", S.fmm_order()}, {"threads", omp_get_max_threads()}, {"eval_s", times[times.size() / 2]},
                            {"min_s", times.front()}, {"max_s", times.back()},
                            {"near_s", (after[Phase::BieNear] - before[Phase::BieNear]) / repeat}, {"far_s", (after[Phase::BieFar] - before[Phase::BieFar]) / repeat},
                            {"sources_s", (after[Phase::BieSources] - before[Phase::BieSources]) / repeat}, {"corrected_layers", S.near_field_lists().corrected_layers()},
                            {"far_rule", S.far_rule() == FarFieldRule::EdgeMidpoints ? "midpoints" : "gauss"},
                            {"construct_s", construct_s}, {"error_uniform_load", err}, {"geometry", geometry}, {"near_ring_layers", ring_layers}, {"singular_points", nv}, {"singular_radial_points", nu},
                            {"error_rotation_load", err_rot}, {"error_normal_load", err_nrm}, {"git", git_hash()}};
        fmt::print("{}\n", j.dump());
        std::fflush(stdout);
      }
  }
  return 0;
}
