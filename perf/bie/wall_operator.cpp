// The fixed wall's operator set up once (FixedWallOptions::reuse_operator, fixed_single_layer.hpp)
// against SingleLayer::apply recomputed at every GMRES iteration, in one run (docs/channel.md §3.2):
//   wall_operator [--per-radius 6,8,12] [--length 6] [--solves 3] [--threads 0] [--backend auto] [--dense-mb 2000]
// On a tube of radius 1 with wall elements 1/per-radius, each wall is solved `solves` times for the
// disturbance of a point force inside it (moved by 0.01 between solves, each solve warm-started
// from the last, as a run does), by the recomputed operator ("old"), by the one set up once with
// its sparse near field and far field ("new, sparse"), and by the one set up once as a dense matrix
// where it fits --dense-mb ("new, dense").
// Prints, per size and operator: the set-up seconds (the FixedWall's construction) and the
// stored operator's and preconditioner's megabytes, the seconds per S_W[f] (mean of 5), the GMRES
// iterations and the seconds per solve and per iteration, and the largest traction difference
// from the old one relative to the traction's largest value; then the ratios old/sparse and old/dense.
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <cstdio>
#include <string>
#include <vector>

#include "capsflow/core/phase_times.hpp"
#include "channel_cases.hpp"

using namespace capsflow;

namespace {

struct Measured {
  double setup = 0, apply = 0, solve = 0, megabytes = 0, preconditioner_megabytes = 0;
  int iterations = 0;
  std::string backend = "";  // the stored operator's far field
  bool converged = true, dense = false;
  Points traction;
};

Measured measure(const ChannelMesh& c, const FixedWallOptions& o, int solves) {
  Measured m;
  Stopwatch clock;
  FixedWall wall(c.mesh, Points::Zero(c.mesh.num_nodes(), 3), o);
  m.setup = clock.seconds();
  m.megabytes = wall.operator_megabytes();
  m.preconditioner_megabytes = wall.preconditioner_megabytes();
  if (wall.fixed_operator()) {
    m.backend = to_string(wall.fixed_operator()->backend());
    m.dense = wall.fixed_operator()->dense();
  }
  const Points ones = Points::Ones(c.mesh.num_nodes(), 3);
  Points u;
  wall.apply(ones, u);  // the FMM's set-up, where it sums by the FMM
  clock.restart();
  for (int k = 0; k < 5; ++k) wall.apply(ones, u);
  m.apply = clock.seconds() / 5;
  Points induced(c.mesh.num_nodes(), 3);
  for (int s = 0; s < solves; ++s) {
    const Vec3 xs(0.01 * s, 0.3, 0.1);
    for (Eigen::Index i = 0; i < induced.rows(); ++i)
      induced.row(i) = channel_cases::point_force_flow(c.mesh.vertices.row(i).transpose(), xs, Vec3(1, 0.2, 0)).transpose();
    const FixedWallSolve r = wall.solve(&induced, 1.0);
    m.solve += r.seconds;
    m.iterations += r.iterations;
    m.converged = m.converged && r.converged;
  }
  m.traction = wall.traction();
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"the fixed wall's operator set up once against recomputed at every iteration"};
  std::vector<double> per_radius{6, 8, 12};
  double length = 6;
  int solves = 3, threads = 0;
  std::string backend = "auto";
  double dense_mb = 2000;
  app.add_option("--per-radius", per_radius, "wall elements per tube radius")->delimiter(',');
  app.add_option("--length", length, "tube length in radii");
  app.add_option("--solves", solves, "solves per wall (warm-started)");
  app.add_option("--threads", threads, "threads (0: OpenMP default)");
  app.add_option("--backend", backend, "far field: auto, fmm or direct");
  app.add_option("--dense-mb", dense_mb, "the dense operator's budget in MB (FixedWallOptions::dense_operator_mb; 0: not measured)");
  CLI11_PARSE(app, argc, argv);
  std::printf("| wall nodes | back end | operator | set-up s | stored MB | preconditioner MB | s per S_W[f] | iterations | s per solve "
              "| s per iteration | traction difference |\n|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const double pr : per_radius) {
    ChannelGeometry g;
    g.length = length, g.element_size = 1 / pr;
    const ChannelMesh c = make_channel_mesh(g);
    FixedWallOptions o;
    o.layer.backend = from_string<BackendRequest>(backend).value_or(BackendRequest::Auto);
    o.layer.threads = threads;
    o.gmres.tolerance = 1e-6;  // a run's: the far field's tolerance (channel_dynamics.cpp)
    o.reuse_operator = false;
    const Measured old = measure(c, o, solves);
    o.reuse_operator = true;
    o.dense_operator_mb = 0;
    const Measured now = measure(c, o, solves);
    o.dense_operator_mb = dense_mb;
    const Measured dense = dense_mb > 0 ? measure(c, o, solves) : Measured{};
    const long nodes = static_cast<long>(c.mesh.num_nodes());
    for (const auto& [name, m] : {std::pair{"old", &old}, std::pair{"new, sparse", &now}, std::pair{"new, dense", &dense}}) {
      if (m == &dense && !dense.dense) continue;
      const std::string difference =
          m == &old ? "" : fmt::format("{:.1e}", (m->traction - old.traction).cwiseAbs().maxCoeff() / old.traction.cwiseAbs().maxCoeff());
      std::printf("| %ld | %s | %s | %.2f | %.1f | %.1f | %.4f | %d%s | %.3f | %.4f | %s |\n", nodes, now.backend.c_str(), name,
                  m->setup, m->megabytes, m->preconditioner_megabytes, m->apply, m->iterations, m->converged ? "" : " (not converged)",
                  m->solve / solves, m->iterations ? m->solve / m->iterations : 0.0, difference.c_str());
    }
    for (const auto& [name, m] : {std::pair{"old/sparse", &now}, std::pair{"old/dense", &dense}})
      if (m->iterations > 0 && (m != &dense || dense.dense))
        std::printf("| %ld | ratio %s | | %.2f | | | %.1f | | %.1f | %.1f | |\n", nodes, name, old.setup / m->setup, old.apply / m->apply,
                    old.solve / m->solve, (old.solve / old.iterations) / (m->solve / m->iterations));
    std::fflush(stdout);
  }
}
