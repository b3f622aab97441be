// double_layer_leaf — the FMM's points per leaf, timed on the double layer's own points:
// sources at the edge midpoints of an icosphere mesh (f = a smooth field times the weight, n = the
// two adjacent elements' summed weighted normals), the nodes as targets, on spheroids of the given
// aspects a/b (a along z). The octree's depth follows the leaf in steps: on these structured points a
// leaf can add a level that random points on the sphere (perf/fmm/leaf_bie.sh) do not, so the
// calibration's leaf is checked here (the Fig. 4 capsule starts as an a/b = 1.4 spheroid). Leaves are interleaved round by round (the host's drift
// falls on every leaf alike); medians of --rounds, wall seconds of setup() + evaluate(), and the last
// round's seconds by pass (last_round_s: tree, p2m, m2m, m2l, x_list, l2l, p2p, l2p, other).
// --kernel stokeslet times the single layer's far field on the same points (f alone).
// One JSON line per (kernel, level, shape, order, densities, leaf).
//   double_layer_leaf --levels 5,6 --aspects 1,1.4,2 --orders 6,7,9,10 --leaves 800,1000,1300,1600 --densities 1,4
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/phase_times.hpp"
#include "capsflow/fmm/fmm.hpp"
#include "capsflow/fmm/stresslet.hpp"

using namespace capsflow;

namespace {
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
struct Case {
  int level;
  double aspect;
  size_t sources, targets;
};

// The last round's time by pass (fmm.hpp's FmmTimings): where a leaf's time goes.
nlohmann::json phases(const fmm::FmmTimings& t) {
  return {{"tree", t.tree}, {"p2m", t.p2m}, {"m2m", t.m2m}, {"m2l", t.m2l}, {"x_list", t.x_list}, {"l2l", t.l2l},
          {"p2p", t.p2p},   {"l2p", t.l2p}, {"other", t.other}};
}

// setup() + evaluate() of one FMM per leaf, the leaves interleaved round by round.
template <class Kernel>
void time_leaves(const Case& c, const std::vector<double>& src, const std::vector<double>& trg, const std::vector<double>& dens,
                 int order, int nd, const std::vector<int>& leaves, int rounds) {
  std::vector<double> many(dens.size() * static_cast<size_t>(nd)), out(Kernel::trg_dim * c.targets * static_cast<size_t>(nd));
  for (int d = 0; d < nd; ++d) std::copy(dens.begin(), dens.end(), many.begin() + static_cast<std::ptrdiff_t>(d * dens.size()));
  std::vector<fmm::Fmm<Kernel>> F;
  for (int leaf : leaves) {
    fmm::FmmOptions o;
    o.order = order;
    o.leaf_size = leaf;
    F.emplace_back(o);
  }
  std::vector<std::vector<double>> wall(leaves.size());
  for (int r = 0; r <= rounds; ++r)  // round 0 warms up (operators loaded, memory touched)
    for (size_t k = 0; k < leaves.size(); ++k) {
      Stopwatch s;
      F[k].setup(src.data(), c.sources, trg.data(), c.targets);
      F[k].evaluate(many.data(), out.data(), nd);
      if (r > 0) wall[k].push_back(s.seconds());
    }
  for (size_t k = 0; k < leaves.size(); ++k) {
    // The tree's work counts: near-field pairs (U list), M2L pairs (V list), W and X list items.
    const fmm::Tree& T = F[k].tree();
    double pairs = 0, v_pairs = 0, wx = 0;
    for (size_t b = 0; b < T.nodes.size(); ++b) {
      const int i = static_cast<int>(b);
      v_pairs += static_cast<double>(T.V.size(i));
      wx += static_cast<double>(T.W.size(i) + T.X.size(i));
      if (!T.nodes[b].leaf) continue;
      for (size_t u = T.U.begin[b]; u < T.U.begin[b + 1]; ++u)
        pairs += static_cast<double>(T.nodes[b].ntrg()) * static_cast<double>(T.nodes[static_cast<size_t>(T.U.item[u])].nsrc());
    }
    fmt::print("{}\n", nlohmann::json{{"kernel", Kernel::name},
                                      {"level", c.level},
                                      {"aspect", c.aspect},
                                      {"sources", c.sources},
                                      {"targets", c.targets},
                                      {"order", order},
                                      {"densities", nd},
                                      {"leaf", leaves[k]},
                                      {"tree_levels", F[k].tree().levels()},
                                      {"tree_nodes", F[k].tree().nodes.size()},
                                      {"near_pairs", pairs},
                                      {"v_pairs", v_pairs},
                                      {"wx_items", wx},
                                      {"threads", omp_get_max_threads()},
                                      {"wall_s", median(wall[k])},
                                      {"last_round_s", phases(F[k].timings())}}
                           .dump());
  }
  std::fflush(stdout);
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"stresslet FMM time by points per leaf on the double layer's edge-midpoint sources"};
  std::vector<int> levels{6}, orders{6, 7, 9, 10}, leaves{800, 1000, 1300, 1600}, densities{1};
  std::vector<double> aspects{1.0, 1.4, 2.0};
  int rounds = 3, threads = 0;
  std::string kernel = "stresslet";
  app.add_option("--levels", levels, "icosahedron levels")->delimiter(',');
  app.add_option("--aspects", aspects, "spheroid aspects a/b (stretched along z; 1: the sphere)")->delimiter(',');
  app.add_option("--orders", orders, "FMM orders")->delimiter(',');
  app.add_option("--leaves", leaves, "points per leaf")->delimiter(',');
  app.add_option("--densities", densities, "densities per evaluate() (the refresh pass takes 4)")->delimiter(',');
  app.add_option("--rounds", rounds, "timed rounds over every leaf (medians reported)");
  app.add_option("--kernel", kernel, "stresslet (the double layer), stokeslet (the single layer's far field, f alone) or both")
      ->check(CLI::IsMember({"stresslet", "stokeslet", "both"}));
  app.add_option("--threads", threads, "OpenMP threads");
  CLI11_PARSE(app, argc, argv);
  if (threads > 0) omp_set_num_threads(threads);
  for (int level : levels)
    for (const double aspect : aspects) {
      const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, level);
      Points x = m.vertices;
      x.col(2) *= aspect;
      // One source per edge: its midpoint, the weighted normals of both sides (weight 1/6 of the
      // element's area-weighted normal per edge-midpoint point), f = w u(y) for a smooth u.
      std::map<std::pair<int, int>, int> edge;
      std::vector<double> src, dens;
      for (Eigen::Index e = 0; e < m.triangles.rows(); ++e) {
        const Vec3 p0 = x.row(m.triangles(e, 0)).transpose(), p1 = x.row(m.triangles(e, 1)).transpose(),
                   p2 = x.row(m.triangles(e, 2)).transpose();
        const Vec3 an = 0.5 * (p1 - p0).cross(p2 - p0) / 3.0;  // per edge midpoint: w ñ = A n / 3
        for (int k = 0; k < 3; ++k) {
          const int a = m.triangles(e, k), b = m.triangles(e, (k + 1) % 3);
          const auto key = std::minmax(a, b);
          auto [it, fresh] = edge.try_emplace(key, static_cast<int>(src.size() / 3));
          if (fresh) {
            const Vec3 y = 0.5 * (x.row(a) + x.row(b)).transpose();
            src.insert(src.end(), {y[0], y[1], y[2]});
            const double w = an.norm();
            dens.insert(dens.end(), {w * (y[1] - 0.3 * y[2]), w * y[0] * y[2], w * (1 + y[0] * y[0]), 0, 0, 0});
          }
          for (int d = 0; d < 3; ++d) dens[6 * static_cast<size_t>(it->second) + 3 + static_cast<size_t>(d)] += an[d];
        }
      }
      const size_t ns = src.size() / 3, nt = static_cast<size_t>(x.rows());
      std::vector<double> trg(3 * nt);
      for (size_t i = 0; i < nt; ++i)
        for (int d = 0; d < 3; ++d) trg[3 * i + static_cast<size_t>(d)] = x(static_cast<Eigen::Index>(i), d);
      // The single layer's Stokeslet takes f alone (its density is q w, as smooth).
      std::vector<double> forces(3 * ns);
      for (size_t j = 0; j < ns; ++j)
        for (int d = 0; d < 3; ++d) forces[3 * j + static_cast<size_t>(d)] = dens[6 * j + static_cast<size_t>(d)];
      const Case c{level, aspect, ns, nt};
      for (int order : orders)
        for (int nd : densities) {
          if (kernel == "stresslet" || kernel == "both") time_leaves<fmm::Stresslet>(c, src, trg, dens, order, nd, leaves, rounds);
          if (kernel == "stokeslet" || kernel == "both") time_leaves<fmm::Stokeslet>(c, src, trg, forces, order, nd, leaves, rounds);
        }
    }
}
