// bie_bench — time and accuracy of one single-layer evaluation on the unit icosphere, per level
// and back end. Accuracy oracle: a uniform load c gives the rigid velocity 2c/3 (μ = 1, a = 1);
// the error is max_i |u_i − 2c/3| / |2c/3|. One JSON line per (level, backend, tolerance).
//   bie_bench --levels 3,4,5,6 --backends direct,fmm --tol 1e-6 --repeat 5 --threads 2
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <nlohmann/json.hpp>

#include "capsflow/core/mesh_generation.hpp"
#include "capsflow/core/single_layer.hpp"
#include "capsflow/core/version.hpp"

using namespace capsflow;

int main(int argc, char** argv) {
  CLI::App app{"single-layer evaluation benchmark"};
  std::vector<int> levels{3, 4, 5};
  std::vector<std::string> backends{"direct", "fmm"};
  std::vector<double> tols{1e-6};
  int repeat = 5, threads = 0;
  app.add_option("--levels", levels, "icosahedron levels")->delimiter(',');
  app.add_option("--backends", backends, "direct,fmm")->delimiter(',');
  app.add_option("--tol", tols, "FMM tolerances")->delimiter(',');
  app.add_option("--repeat", repeat, "timed evaluations (median reported)");
  app.add_option("--threads", threads, "OpenMP threads");
  CLI11_PARSE(app, argc, argv);
  if (threads > 0) omp_set_num_threads(threads);
  const Vec3 c(0.3, -1.0, 0.5);
  for (int level : levels) {
    const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, level);
    Points q(m.num_nodes(), 3);
    q.rowwise() = c.transpose();
    for (const auto& b : backends)
      for (double tol : tols) {
        if (b == "direct" && tol != tols.front()) continue;
        SingleLayerOptions o;
        o.backend = b;
        o.tolerance = tol;
        const auto t_setup = std::chrono::steady_clock::now();
        SingleLayer S(m.triangles, m.num_nodes(), o);
        const double construct_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_setup).count();
        Points u;
        S.apply(m.vertices, q, u);  // warm-up (first touch, FMM operator cache)
        std::vector<double> times;
        SingleLayerTimings before = S.timings();
        for (int r = 0; r < repeat; ++r) {
          const auto t0 = std::chrono::steady_clock::now();
          S.apply(m.vertices, q, u);
          times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        }
        const SingleLayerTimings after = S.timings();
        std::sort(times.begin(), times.end());
        const double err = (u.rowwise() - (2.0 / 3.0) * c.transpose()).rowwise().norm().maxCoeff() / ((2.0 / 3.0) * c.norm());
        nlohmann::json j = {{"what", "single_layer"}, {"level", level}, {"elements", m.num_elements()}, {"nodes", m.num_nodes()},
                            {"sources", 3 * m.num_elements()}, {"backend", b}, {"tol", b == "fmm" ? tol : 0.0},
                            {"order", S.fmm_order()}, {"threads", omp_get_max_threads()}, {"eval_s", times[times.size() / 2]},
                            {"min_s", times.front()}, {"max_s", times.back()},
                            {"near_s", (after.near - before.near) / repeat}, {"far_s", (after.far - before.far) / repeat},
                            {"construct_s", construct_s}, {"error_uniform_load", err}, {"git", git_hash()}};
        fmt::print("{}\n", j.dump());
        std::fflush(stdout);
      }
  }
  return 0;
}
