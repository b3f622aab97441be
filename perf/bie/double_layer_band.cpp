// double_layer_band — how many edge hops of 3-point Gauss correction (the band, §4.2.2) the double
// layer's edge-midpoint far field needs (docs/boundary-integral.md §4.7.3). D_h[u] at every node,
// with the band m = 1 (none beyond the near ring) … 4 and with the Gauss-point far field (6N
// sources, before the edge-midpoint rule), against a reference whose 7-point ring reaches 3 hops and whose band
// reaches 8; largest node difference relative to max |u|. On the unit sphere also the error of the
// default (kAutoDoubleLayerCorrectedLayers) and of the reference against the exact eigenvalue: the
// discretisation error, which the quadrature error must stay well below.
//   double_layer_band --levels 3,4,5
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <functional>
#include <string>
#include <vector>

#include "capsflow/core/bie/double_layer.hpp"
#include "capsflow/core/mesh/generation.hpp"

using namespace capsflow;

namespace {

Points apply(const SurfaceMesh& m, const Points& x, const Points& u, int ring, int band, FarFieldRule rule) {
  DoubleLayerOptions o;
  o.backend = BackendRequest::Direct;
  o.near_ring_layers = ring;
  o.corrected_layers = band;
  o.far_rule = rule;
  DoubleLayer D(m.triangles, m.num_nodes(), o);
  D.set_surface(x);
  Points out;
  D.apply(u, out);
  return out;
}

double max_rel(const Points& a, const Points& b, const Points& u) {
  return (a - b).rowwise().norm().maxCoeff() / u.rowwise().norm().maxCoeff();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"double_layer_band"};
  std::vector<int> levels{3, 4};
  app.add_option("--levels", levels, "icosahedron levels")->delimiter(',');
  CLI11_PARSE(app, argc, argv);
  struct Case {
    std::string name;
    double aspect;
    std::function<Vec3(const Vec3&)> u;
    double mu;  // exact eigenvalue on the unit sphere (0: none)
  };
  const std::vector<Case> cases = {
      {"sphere, exterior n=2", 1.0, [](const Vec3& x) { return Vec3(Vec3(x.y(), x.x(), 0) - 5 * x.x() * x.y() * x); }, -3.0 / 70},
      {"sphere, toroidal n=2", 1.0, [](const Vec3& x) { return Vec3(x.cross(Vec3(x.y(), x.x(), 0))); }, 3.0 / 10},
      {"spheroid a/b=2, smooth u", 2.0,
       [](const Vec3& x) { return Vec3(x.y() - 0.3 * x.z(), x.x() * x.z(), 1.0 + x.x() * x.x()); }, 0.0},
  };
  fmt::print("{:<26} {:>5} {:>10} {:>10} {:>10} {:>10} {:>10} {:>12} {:>10}\n", "case", "level", "m=1", "m=2", "m=3",
             "m=4", "gauss 6N", "default-exact", "ref-exact");
  for (const auto& c : cases)
    for (int level : levels) {
      const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, level);
      Points x = m.vertices, u(m.num_nodes(), 3);
      x.col(2) *= c.aspect;
      for (Eigen::Index i = 0; i < x.rows(); ++i) u.row(i) = c.u(x.row(i).transpose()).transpose();
      const Points ref = apply(m, x, u, 3, 8, FarFieldRule::EdgeMidpoints);
      std::vector<double> d;
      for (int band = 1; band <= 4; ++band) d.push_back(max_rel(apply(m, x, u, 1, band, FarFieldRule::EdgeMidpoints), ref, u));
      d.push_back(max_rel(apply(m, x, u, 1, 1, FarFieldRule::GaussPoints), ref, u));
      // The discretisation error: the default band (0 = auto) and the reference against the exact value.
      const Points def = apply(m, x, u, 1, 0, FarFieldRule::EdgeMidpoints);
      const double exact = c.mu != 0 ? max_rel(def, c.mu * u, u) : 0.0, ref_exact = c.mu != 0 ? max_rel(ref, c.mu * u, u) : 0.0;
      fmt::print("{:<26} {:>5} {:>10.2e} {:>10.2e} {:>10.2e} {:>10.2e} {:>10.2e} {:>12.2e} {:>10.2e}\n", c.name, level, d[0], d[1],
                 d[2], d[3], d[4], exact, ref_exact);
    }
}
