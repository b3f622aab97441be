// far_rule_accuracy — which far-field rule the single layer can afford (docs/boundary-integral.md
// §4.2.1). For sampled nodes x_i of a sphere (or spheroid) mesh it integrates every element by
//   the exact closed form if it touches x_i, Dunavant's 7-point rule on the first `ring` hop
//   layers, the 3-point Gauss rule on the layers up to m, and a cheap rule R beyond m,
// for R = vertex (nodal sources, N of them), centroid (2N), edge midpoint (3N, shared by the two
// elements of an edge), vertex + centroid (degree 2, 3N), and the 3-point Gauss rule itself (6N,
// the far field before the edge-midpoint rule), and compares with a converged integral over the same surface
// (adaptive subdivision until every part is 8 of its sizes away) and, on the sphere, with the
// classical solutions. Max over the sampled nodes, relative to max |u|.
//   far_rule_accuracy --level 4 --targets 30 [--geometry curved] [--aspect 4] [--ring 1] [--max-layers 8]
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <queue>
#include <random>
#include <vector>

#include "capsflow/core/bie/curved_triangle.hpp"
#include "capsflow/core/bie/point_triangle.hpp"
#include "capsflow/core/bie/quadrature.hpp"
#include "capsflow/core/mesh/generation.hpp"

using namespace capsflow;

namespace {

struct Rule {
  const char* name;
  std::vector<std::array<double, 4>> points;  // λ0, λ1, λ2, weight (weights sum to 1)
};

const std::vector<Rule>& rules() {
  static const std::vector<Rule> r = {
      {"gauss3 (6N, before)", {{2. / 3, 1. / 6, 1. / 6, 1. / 3}, {1. / 6, 2. / 3, 1. / 6, 1. / 3}, {1. / 6, 1. / 6, 2. / 3, 1. / 3}}},
      {"vertex (N)", {{1, 0, 0, 1. / 3}, {0, 1, 0, 1. / 3}, {0, 0, 1, 1. / 3}}},
      {"centroid (2N)", {{1. / 3, 1. / 3, 1. / 3, 1}}},
      {"midpoint (3N)", {{.5, .5, 0, 1. / 3}, {0, .5, .5, 1. / 3}, {.5, 0, .5, 1. / 3}}},
      {"vertex+centroid (3N)", {{1, 0, 0, 1. / 12}, {0, 1, 0, 1. / 12}, {0, 0, 1, 1. / 12}, {1. / 3, 1. / 3, 1. / 3, .75}}},
  };
  return r;
}

// ∫ over the part of T with parent barycentrics `bary` (rows) of G(p − y) q(y) dS, refined until
// the part is 8 of its sizes away from p.
Vec3 adaptive(const QuadraticTriangle& T, const Vec3 (&q)[3], const Vec3& p, const Eigen::Matrix3d& bary, double area, int depth) {
  Vec3 y[3];
  for (int v = 0; v < 3; ++v) y[v] = T.position(bary(v, 1), bary(v, 2));
  const double diam = std::max({(y[1] - y[0]).norm(), (y[2] - y[1]).norm(), (y[0] - y[2]).norm()});
  if (point_triangle_distance(p, y[0], y[1], y[2]) > 8 * diam || depth >= 12) {
    Vec3 sum = Vec3::Zero();
    for (const auto& r : kDunavant7) {
      const Eigen::RowVector3d l = r[0] * bary.row(0) + r[1] * bary.row(1) + r[2] * bary.row(2);
      sum += (r[3] * area * T.jacobian(l[1], l[2])) * stokeslet_apply(p - T.position(l[1], l[2]), l[0] * q[0] + l[1] * q[1] + l[2] * q[2]);
    }
    return sum;
  }
  Vec3 sum = Vec3::Zero();
  for (const auto& sub : split_in_four(bary)) sum += adaptive(T, q, p, sub, area / 4, depth + 1);
  return sum;
}

Vec3 apply_rule(const std::vector<std::array<double, 4>>& pts, const QuadraticTriangle& T, const Vec3 (&q)[3], const Vec3& p) {
  Vec3 s = Vec3::Zero();
  for (const auto& r : pts)
    s += (0.5 * r[3] * T.jacobian(r[1], r[2])) * stokeslet_apply(p - T.position(r[1], r[2]), r[0] * q[0] + r[1] * q[1] + r[2] * q[2]);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"far-field rule accuracy of the single layer"};
  int level = 3, n_targets = 40, ring = 1, max_layers = 8;
  std::string geometry = "flat";
  double aspect = 1;
  app.add_option("--level", level, "icosphere level");
  app.add_option("--targets", n_targets, "sampled nodes (random, fixed seed)");
  app.add_option("--geometry", geometry, "flat or curved");
  app.add_option("--aspect", aspect, "prolate spheroid a/b (1: the unit sphere, with analytic errors)");
  app.add_option("--ring", ring, "hop layers of the 7-point ring");
  app.add_option("--max-layers", max_layers, "largest m tried");
  CLI11_PARSE(app, argc, argv);
  const bool curved = geometry == "curved", sphere = aspect == 1;
  SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, level);
  if (!sphere) {
    const double b = 1 / std::cbrt(aspect), a = aspect * b;
    m.vertices.col(0) *= b, m.vertices.col(1) *= b, m.vertices.col(2) *= a;
  }
  const Points& x = m.vertices;
  const Triangles& tri = m.triangles;
  const Eigen::Index N = x.rows(), M = tri.rows();
  Points nrm;
  vertex_normals_max(x, tri, nrm);
  auto element = [&](Eigen::Index e, int first) {
    const int a = tri(e, first), b = tri(e, (first + 1) % 3), c = tri(e, (first + 2) % 3);
    const Vec3 xa = x.row(a), xb = x.row(b), xc = x.row(c);
    if (!curved) return QuadraticTriangle::flat(xa, xb, xc);
    const Vec3 na = nrm.row(a), nb = nrm.row(b), nc = nrm.row(c);
    return QuadraticTriangle(xa, xb, xc, hermite_edge_midpoint(xa, xb, na, nb), hermite_edge_midpoint(xb, xc, nb, nc),
                             hermite_edge_midpoint(xc, xa, nc, na));
  };
  // Loads: smooth, uniform (exact 2c/3 on the sphere), rotational ω × n (ω × x/3), normal (0).
  const Vec3 c(0.3, -1.0, 0.5), omega(0.2, 0.7, -0.4);
  const char* load_name[4] = {"smooth", "uniform", "rotation", "normal"};
  std::vector<Points> loads(4, Points(N, 3));
  for (Eigen::Index i = 0; i < N; ++i) {
    const Vec3 p = x.row(i);
    loads[0].row(i) << std::sin(2 * p[0]) + 0.3, p[1] * p[2], std::cos(p[2]);
    loads[1].row(i) = c.transpose();
    loads[2].row(i) = omega.cross(p).transpose();
    loads[3].row(i) = p.transpose();
  }
  std::vector<std::vector<int>> adj(static_cast<size_t>(N));
  for (Eigen::Index e = 0; e < M; ++e)
    for (int k = 0; k < 3; ++k) adj[static_cast<size_t>(tri(e, k))].push_back(tri(e, (k + 1) % 3)),
        adj[static_cast<size_t>(tri(e, (k + 1) % 3))].push_back(tri(e, k));
  std::vector<Eigen::Index> targets;
  std::mt19937 gen(1);
  std::uniform_int_distribution<Eigen::Index> pick(0, N - 1);
  for (int t = 0; t < n_targets; ++t) targets.push_back(n_targets >= N ? t % N : pick(gen));
  const auto& R = rules();
  const size_t nr = R.size(), nm = static_cast<size_t>(max_layers) + 1;
  // err[load][rule][m] against the reference, ana[load][rule][m] against the classical solution.
  std::vector<double> err(4 * nr * nm, 0), ana(4 * nr * nm, 0), scale(4, 0), ref_ana(4, 0);
  const GaussLegendre rv(8), ru(6);
  for (Eigen::Index i : targets) {
    std::vector<int> hop(static_cast<size_t>(N), -1);
    std::queue<int> fifo;
    hop[static_cast<size_t>(i)] = 0, fifo.push(static_cast<int>(i));
    while (!fifo.empty()) {
      const int v = fifo.front();
      fifo.pop();
      for (int w : adj[static_cast<size_t>(v)])
        if (hop[static_cast<size_t>(w)] < 0) hop[static_cast<size_t>(w)] = hop[static_cast<size_t>(v)] + 1, fifo.push(w);
    }
    const Vec3 p = x.row(i);
    for (int L = 0; L < 4; ++L) {
      const Points& q = loads[static_cast<size_t>(L)];
      Vec3 ref = Vec3::Zero();
      std::vector<Vec3> sum(nr * nm, Vec3::Zero());
      for (Eigen::Index e = 0; e < M; ++e) {
        const int layer = std::min({hop[static_cast<size_t>(tri(e, 0))], hop[static_cast<size_t>(tri(e, 1))], hop[static_cast<size_t>(tri(e, 2))]});
        if (layer == 0) {  // touching: the closed form (+ Duffy for curved), common to every variant
          const int k0 = tri(e, 0) == i ? 0 : (tri(e, 1) == i ? 1 : 2);
          const auto S = singular_element_integral(element(e, k0), rv, ru);
          Vec3 exact = Vec3::Zero();
          for (int k = 0; k < 3; ++k) exact += S[static_cast<size_t>(k)] * q.row(tri(e, (k0 + k) % 3)).transpose();
          ref += exact;
          for (auto& s : sum) s += exact;
          continue;
        }
        const QuadraticTriangle T = element(e, 0);
        const Vec3 qe[3] = {q.row(tri(e, 0)).transpose(), q.row(tri(e, 1)).transpose(), q.row(tri(e, 2)).transpose()};
        ref += adaptive(T, qe, p, Eigen::Matrix3d::Identity(), 0.5, 0);
        std::vector<std::array<double, 4>> d7;
        for (const auto& r : kDunavant7) d7.push_back({r[0], r[1], r[2], r[3]});
        const Vec3 inside = layer <= ring ? apply_rule(d7, T, qe, p) : apply_rule(R[0].points, T, qe, p);
        for (size_t r = 0; r < nr; ++r) {
          const Vec3 beyond = apply_rule(R[r].points, T, qe, p);
          for (size_t mm = 1; mm < nm; ++mm) sum[r * nm + mm] += layer <= static_cast<int>(mm) ? inside : beyond;
        }
      }
      const double s8 = 1 / (8 * M_PI);
      ref *= s8;
      const Vec3 exact = L == 1 ? Vec3(2.0 / 3 * c) : (L == 2 ? Vec3(omega.cross(p) / 3) : Vec3::Zero());
      scale[static_cast<size_t>(L)] = std::max(scale[static_cast<size_t>(L)], ref.norm());
      if (sphere && L > 0) ref_ana[static_cast<size_t>(L)] = std::max(ref_ana[static_cast<size_t>(L)], (ref - exact).norm());
      for (size_t k = 0; k < nr * nm; ++k) {
        err[static_cast<size_t>(L) * nr * nm + k] = std::max(err[static_cast<size_t>(L) * nr * nm + k], (s8 * sum[k] - ref).norm());
        if (sphere && L > 0) ana[static_cast<size_t>(L) * nr * nm + k] = std::max(ana[static_cast<size_t>(L) * nr * nm + k], (s8 * sum[k] - exact).norm());
      }
    }
  }
  // The classical solutions' own scales: |2c/3|, |ω|/3, and 2/3 for the normal load (zero velocity).
  const double ana_scale[4] = {1, 2.0 / 3 * c.norm(), omega.norm() / 3, 2.0 / 3};
  fmt::print("level {} ({} elements), {}, aspect {}, 7-point ring {} layer(s), {} sampled nodes\n", level, M, geometry, aspect, ring,
             targets.size());
  fmt::print("error of the operator against the converged integral over the same surface, max over nodes / max |u|;\n"
             "columns: m = the last hop layer integrated by the 7-point / 3-point rules, the cheap rule beyond\n");
  for (int L = 0; L < 4; ++L) {
    const double sc = L == 3 ? ana_scale[3] : scale[static_cast<size_t>(L)];  // the normal load's u is ~0
    fmt::print("{} load{}\n", load_name[L],
               sphere && L > 0 ? fmt::format(" (surface itself against the classical solution: {:.2e})", ref_ana[static_cast<size_t>(L)] / ana_scale[L]) : "");
    for (size_t r = 0; r < nr; ++r) {
      std::string row = fmt::format("  {:<22}", R[r].name);
      for (size_t mm = 1; mm < nm; ++mm) row += fmt::format(" m{} {:.2e}", mm, err[static_cast<size_t>(L) * nr * nm + r * nm + mm] / sc);
      fmt::print("{}\n", row);
      if (sphere && L > 0) {
        std::string a = fmt::format("  {:<22}", "  against classical");
        for (size_t mm = 1; mm < nm; ++mm) a += fmt::format(" m{} {:.2e}", mm, ana[static_cast<size_t>(L) * nr * nm + r * nm + mm] / ana_scale[L]);
        fmt::print("{}\n", a);
      }
    }
  }
  return 0;
}
