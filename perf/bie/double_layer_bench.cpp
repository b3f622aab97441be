// double_layer_bench — the double layer's cost per evaluation on an a/b = 2 spheroid: set-up per
// phase (sources, far field, near-field blocks) and one application, as wall and CPU seconds
// (CPU/wall = busy threads; CPU seconds stay comparable on a loaded machine), medians of --repeat;
// and the set-up with its first application fused (set_surface(x, &u, &Du), as the viscosity-ratio
// solve calls it), with its largest difference from set_surface + apply.
// One JSON line per level.
//   double_layer_bench --levels 4,6 --repeat 5 --threads 2 [--backend direct|fmm|auto] [--tol 1e-6] [--reuse 0]
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <vector>

#include "capsflow/core/bie/double_layer.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/phase_times.hpp"

using namespace capsflow;

namespace {
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"double-layer set-up and application benchmark"};
  std::vector<int> levels{4};
  std::string backend = "auto";
  double tol = 1e-6;
  int repeat = 5, threads = 0;
  app.add_option("--levels", levels, "icosahedron levels")->delimiter(',');
  app.add_option("--backend", backend, "auto, direct or fmm");
  app.add_option("--tol", tol, "fluid tolerance");
  app.add_option("--repeat", repeat, "timed set-ups and applications (medians reported)");
  app.add_option("--threads", threads, "OpenMP threads");
  bool reuse = true;
  app.add_option("--reuse", reuse, "reuse D̃[1]'s quadrature error between set-ups (fluid.reuse_identity_term); "
                                   "0: every set-up is the full pass");
  CLI11_PARSE(app, argc, argv);
  if (threads > 0) omp_set_num_threads(threads);
  for (int level : levels) {
    const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, level);
    Points x = m.vertices, u(m.num_nodes(), 3);
    x.col(2) *= 2.0;  // a/b = 2: no exact symmetry helps
    for (Eigen::Index i = 0; i < x.rows(); ++i)
      u.row(i) << x(i, 1) - 0.3 * x(i, 2), x(i, 0) * x(i, 2), 1.0 + x(i, 0) * x(i, 0);
    DoubleLayerOptions o;
    o.backend = from_string<BackendRequest>(backend).value();
    o.tolerance = tol;
    o.reuse_identity_term = reuse;
    DoubleLayer D(m.triangles, m.num_nodes(), o);
    Points out;
    std::vector<double> setup_wall, setup_cpu, apply_wall, apply_cpu, fused_wall, fused_cpu;
    std::vector<std::vector<double>> phase_cpu(3);
    const Phase phases[3] = {Phase::BieSources, Phase::BieFar, Phase::BieNear};
    D.set_surface(x);  // first touch
    D.apply(u, out);
    for (int r = 0; r < repeat; ++r) {
      const PhaseTimes before = D.times();
      Stopwatch s;
      D.set_surface(x);
      setup_wall.push_back(s.seconds()), setup_cpu.push_back(s.cpu_seconds());
      for (int p = 0; p < 3; ++p) phase_cpu[p].push_back(D.times().cpu(phases[p]) - before.cpu(phases[p]));
      Stopwatch a;
      D.apply(u, out);
      apply_wall.push_back(a.seconds()), apply_cpu.push_back(a.cpu_seconds());
    }
    Points fused;
    for (int r = 0; r < repeat; ++r) {
      Stopwatch s;
      D.set_surface(x, &u, &fused);
      fused_wall.push_back(s.seconds()), fused_cpu.push_back(s.cpu_seconds());
    }
    const double fused_diff = (fused - out).cwiseAbs().maxCoeff() / out.cwiseAbs().maxCoeff();
    // Inexact applications (single-precision far-field pairs where the build allows them): time
    // and error, relative in L2 to the exact image, for the smooth u and for a random field.
    std::vector<double> inexact_wall, inexact_cpu;
    Points rough = Points::Random(u.rows(), 3), exact_rough, inexact, inexact_rough;
    for (int r = 0; r < repeat; ++r) {
      Stopwatch s;
      D.apply(u, inexact, 1.0);
      inexact_wall.push_back(s.seconds()), inexact_cpu.push_back(s.cpu_seconds());
    }
    D.apply(rough, exact_rough);
    D.apply(rough, inexact_rough, 1.0);
    const double inexact_err = (inexact - out).norm() / out.norm(),
                 inexact_err_rough = (inexact_rough - exact_rough).norm() / exact_rough.norm();
    nlohmann::json j{{"level", level},
                     {"elements", m.triangles.rows()},
                     {"backend", to_string(D.backend())},
                     {"tolerance", tol},
                     {"threads", omp_get_max_threads()},
                     {"setup_wall_s", median(setup_wall)},
                     {"setup_cpu_s", median(setup_cpu)},
                     {"setup_sources_cpu_s", median(phase_cpu[0])},
                     {"setup_far_cpu_s", median(phase_cpu[1])},
                     {"setup_near_cpu_s", median(phase_cpu[2])},
                     {"apply_wall_s", median(apply_wall)},
                     {"apply_cpu_s", median(apply_cpu)},
                     {"setup_and_apply_fused_wall_s", median(fused_wall)},
                     {"setup_and_apply_fused_cpu_s", median(fused_cpu)},
                     {"fused_max_rel_difference", fused_diff},
                     {"inexact_apply_wall_s", median(inexact_wall)},
                     {"inexact_apply_cpu_s", median(inexact_cpu)},
                     {"inexact_rel_l2_smooth", inexact_err},
                     {"inexact_rel_l2_random", inexact_err_rough},
                     {"checksum", out.sum()}};
    fmt::print("{}\n", j.dump());
  }
}
