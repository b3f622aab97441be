// double_layer_fmm_order — the double layer's far-field FMM error by order, against the direct sum,
// measured where the viscosity-ratio solve needs it: relative to the density ‖u‖ (the Krylov
// operator's contract, gmres.hpp: an error of at most ε‖v‖ in the nodal-area norm) and relative to
// the image ‖D u‖ (the FMM calibration's measure, fmm/calibration.hpp). For a smooth density the
// two agree (D u ≈ u/2 in size); for a rough one the image is far smaller than the density, so the
// calibration's worst case (random f with outward normals) overstates what the solve needs.
// One JSON line per (level, order, density: smooth, random, and the unit constants unit_x/y/z that the
// D̃[1] refresh pass sums), on an a/b = 2 spheroid; wall seconds of one apply().
//   double_layer_fmm_order --levels 5,6 --orders 7,8,9,10,11 --threads 2
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <omp.h>

#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <vector>

#include "capsflow/core/bie/double_layer.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/phase_times.hpp"
#include "capsflow/core/rhs/volume_constraint.hpp"

using namespace capsflow;

int main(int argc, char** argv) {
  CLI::App app{"double-layer FMM error by order, relative to the density and to the image"};
  std::vector<int> levels{5}, orders{7, 8, 9, 10, 11};
  int threads = 0;
  unsigned seed = 1;
  app.add_option("--levels", levels, "icosahedron levels")->delimiter(',');
  app.add_option("--orders", orders, "FMM orders")->delimiter(',');
  app.add_option("--threads", threads, "OpenMP threads");
  app.add_option("--seed", seed, "seed of the random density");
  CLI11_PARSE(app, argc, argv);
  if (threads > 0) omp_set_num_threads(threads);
  for (int level : levels) {
    const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, level);
    Points x = m.vertices;
    x.col(2) *= 2.0;  // a/b = 2: no exact symmetry helps
    Points a;
    volume_gradient(x, m.triangles, a);
    const Eigen::VectorXd w = a.rowwise().norm();  // nodal areas: the solve's inner product
    auto norm = [&](const Points& v) { return std::sqrt((w.array() * v.rowwise().squaredNorm().array()).sum()); };
    std::srand(seed);
    Points smooth(m.num_nodes(), 3), rough = Points::Random(m.num_nodes(), 3);
    for (Eigen::Index i = 0; i < x.rows(); ++i)
      smooth.row(i) << x(i, 1) - 0.3 * x(i, 2), x(i, 0) * x(i, 2), 1.0 + x(i, 0) * x(i, 0);
    DoubleLayerOptions direct;
    direct.backend = BackendRequest::Direct;
    direct.reuse_identity_term = false;
    DoubleLayer ref(m.triangles, m.num_nodes(), direct);
    ref.set_surface(x);
    // The densities: a smooth field, a random one (a Krylov vector), and the three unit constants
    // (the refresh pass's densities of D̃[1], boundary-integral.md §4.7.5).
    std::vector<Points> dens{smooth, rough};
    const char* names[] = {"smooth", "random", "unit_x", "unit_y", "unit_z"};
    for (int c = 0; c < 3; ++c) {
      Points e = Points::Zero(m.num_nodes(), 3);
      e.col(c).setOnes();
      dens.push_back(e);
    }
    std::vector<Points> refs(dens.size());
    for (size_t k = 0; k < dens.size(); ++k) ref.apply(dens[k], refs[k]);
    for (int p : orders) {
      DoubleLayerOptions o = direct;
      o.backend = BackendRequest::Fmm;
      o.fmm_order = p;
      DoubleLayer D(m.triangles, m.num_nodes(), o);
      D.set_surface(x);
      for (size_t k = 0; k < dens.size(); ++k) {
        const Points& u = dens[k];
        const Points& r = refs[k];
        Points out;
        D.apply(u, out);  // the first application pays for the FMM's tree
        Stopwatch s;
        D.apply(u, out);
        const double seconds = s.seconds();
        // The difference is the far field's: that of u, and that of D̃[1] (summed by the same FMM in
        // the set-up, and multiplied by u_i on the diagonal) — both what an application errs by.
        const Points e = out - r;
        nlohmann::json j{{"level", level},
                         {"elements", m.triangles.rows()},
                         {"order", p},
                         {"density", names[k]},
                         {"threads", omp_get_max_threads()},
                         {"apply_wall_s", seconds},
                         {"image_over_density", norm(r) / norm(u)},
                         {"error_rel_density", norm(e) / norm(u)},
                         {"error_rel_image", norm(e) / norm(r)},
                         {"max_error_rel_density_max", e.rowwise().norm().maxCoeff() / u.rowwise().norm().maxCoeff()}};
        fmt::print("{}\n", j.dump());
      }
    }
  }
}
