// multi_surface_bench — one single-layer evaluation over K unit spheres against K times one sphere
// alone (the same mesh, back end chosen from the total counts as a run would), and the cost of the
// cross-surface near field. Layouts: a cubic lattice of K spheres with centre spacing --spacing
// radii (2.5: gaps of half a radius, no cross pairs at level ≥ 4), or a pair at a gap of --gap
// element sizes (cross pairs). Load: uniform per sphere. One JSON line per (K, layout).
//   multi_surface_bench --level 4 --counts 1,2,8,32 --spacing 2.5 --repeat 5 --threads 2
//   multi_surface_bench --level 4 --counts 2 --gap 0.2 --repeat 5 --threads 2
// The direct sum is at 1e-6 and the FMM at --fmm-tolerance, as in a run (docs/boundary-integral.md §4.3.2).
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "capsflow/core/bie/multi_surface_single_layer.hpp"
#include "capsflow/core/io/version.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/mesh/stats.hpp"

using namespace capsflow;
using clk = std::chrono::steady_clock;

namespace {

double seconds(clk::time_point a, clk::time_point b) { return std::chrono::duration<double>(b - a).count(); }

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// K centres: a cubic lattice of spacing s, filled in x, then y, then z.
std::vector<Vec3> lattice(int K, double s) {
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(K)) - 1e-9));
  std::vector<Vec3> c;
  for (int k = 0; k < K; ++k) c.emplace_back(s * (k % side), s * ((k / side) % side), s * (k / (side * side)));
  return c;
}

}  // namespace

// The single layer's phases (near, far, sources, ...) per evaluation, from its cumulative times.
nlohmann::json phases_per_evaluation(const PhaseTimes& t, int evaluations) {
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t i = 0; i < kPhaseNames.size(); ++i)
    if (const double s = t[static_cast<Phase>(i)]; s > 0) j[kPhaseNames[i]] = s / evaluations;
  return j;
}

int main(int argc, char** argv) {
  CLI::App app{"single layer over several surfaces: cost against one surface"};
  int level = 4, repeat = 5, threads = 0;
  std::vector<int> counts{1, 2, 8};
  double spacing = 2.5, gap = -1, fmm_tolerance = 1e-5;
  std::string backend = "auto";
  app.add_option("--level", level, "icosahedron level of every sphere");
  app.add_option("--counts", counts, "numbers of spheres")->delimiter(',');
  app.add_option("--spacing", spacing, "lattice spacing of the centres, in radii");
  app.add_option("--gap", gap, "a pair at this gap in element sizes (overrides the lattice; counts must be 2)");
  app.add_option("--backend", backend, "auto, direct or fmm");
  app.add_option("--fmm-tolerance", fmm_tolerance, "the FMM's tolerance (1e-5: a run's fluid.tolerance = \"auto\" under error control)");
  app.add_option("--repeat", repeat, "evaluations timed (median)");
  int leaf = 0;
  app.add_option("--fmm-leaf-size", leaf, "points per FMM leaf (0: the calibrated one)");
  app.add_option("--threads", threads, "OpenMP threads (0: all)");
  CLI11_PARSE(app, argc, argv);
  if (threads > 0) omp_set_num_threads(threads);
  const SurfaceMesh one = make_sphere_mesh(BaseSolid::Icosahedron, level);
  const double h = mesh_stats(one).edge_max;  // the element size the gap is counted in
  SingleLayerOptions opt;
  opt.fmm_tolerance = fmm_tolerance;
  opt.fmm_leaf_size = leaf;
  opt.backend = backend == "direct" ? BackendRequest::Direct : backend == "fmm" ? BackendRequest::Fmm : BackendRequest::Auto;
  double single_seconds = 0;
  for (int K : counts) {
    std::vector<Vec3> centres = lattice(K, spacing);
    if (gap >= 0) {
      if (K != 2) throw std::invalid_argument("--gap needs --counts 2");
      centres = {Vec3::Zero(), (2 + gap * h) * one.vertices.row(0).transpose().normalized()};
    }
    std::vector<SurfaceMesh> parts;
    for (const Vec3& c : centres) {
      SurfaceMesh m = one;
      m.vertices.rowwise() += c.transpose();
      parts.push_back(m);
    }
    const SurfaceSet set(parts);
    Points q(set.mesh().num_nodes(), 3), u;
    for (int k = 0; k < K; ++k)
      q.middleRows(set.part(k).node_begin, set.part(k).nodes).rowwise() = Eigen::RowVector3d(0.3 + 0.1 * k, -0.2, 1.0);
    MultiSurfaceSingleLayer S(set, opt);
    S.apply(set.mesh().vertices, q, u);  // set-up and first touch, not timed
    std::vector<double> total, cross;
    for (int r = 0; r < repeat; ++r) {
      const auto t0 = clk::now();
      S.apply(set.mesh().vertices, q, u);
      total.push_back(seconds(t0, clk::now()));
      CrossNearField c(set, kCrossNearRatio, threads);
      const auto t1 = clk::now();
      c.find_pairs(set.mesh().vertices);
      Points du = Points::Zero(u.rows(), 3);
      c.correct(set.mesh().vertices, q, S.layer(), du);
      cross.push_back(seconds(t1, clk::now()));
    }
    const double t = median(total);
    if (K == 1) single_seconds = t;
    nlohmann::json j{{"bench", "multi_surface"},
                     {"level", level},
                     {"elements_per_surface", one.num_elements()},
                     {"surfaces", K},
                     {"layout", gap >= 0 ? fmt::format("pair at {} h", gap) : fmt::format("lattice {} radii", spacing)},
                     {"backend", to_string(S.layer().backend())},
                     {"fmm_order", S.layer().fmm_order()},
                     {"threads", omp_get_max_threads()},
                     {"median_seconds", t},
                     {"per_surface_over_one", single_seconds > 0 ? t / (K * single_seconds) : 0.0},
                     {"cross_pairs", S.cross().pairs()},
                     {"cross_median_seconds", median(cross)},
                     {"closest_gap_in_h", S.closest().ratio},
                     {"phase_seconds_per_evaluation", phases_per_evaluation(S.layer().times(), repeat + 1)},
                     {"git", git_hash()}};
    fmt::print("{}\n", j.dump());
  }
  return 0;
}
