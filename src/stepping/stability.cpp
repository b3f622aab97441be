#include "capsflow/core/stepping/stability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "capsflow/core/rhs/wall_factory.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

double StabilityEstimate::limit() const { return std::min({membrane, bending, flow}); }

std::string StabilityEstimate::limiting() const {
  const double l = limit();
  return l == membrane ? "membrane" : (l == bending ? "bending" : "flow");
}

double area_to_shear_modulus_ratio(const Scene& s) {
  // K_s/G_s = (1 + ν_s)/(1 − ν_s) with the law's own small-strain ν_s (shell/laws.hpp):
  // 3 for NH, 1 + 2C for Skalak, (1 + ν)/(1 − ν) for generalized Hooke.
  const double nu_s = scene_law(s).nu_s();
  return (1.0 + nu_s) / (1.0 - nu_s);
}

StabilityEstimate stability_estimate(const Scene& s, double dx) {
  StabilityEstimate e;
  const double ca = s.flow.ca_s;
  // The mesh-scale modes see a locally flat wall, where the double layer vanishes: their
  // relaxation rates are 2/(1 + λ) times those at λ = 1 (docs/time-integration.md §5.9.4).
  const double viscosity = 0.5 * (1.0 + s.fluid.viscosity_ratio);
  e.membrane = viscosity * kMembraneConstant / (1.0 + area_to_shear_modulus_ratio(s)) * ca * dx;
  e.bending = std::numeric_limits<double>::infinity();
  if (s.wall.model == WallModel::Gsmb) {
    const double a = s.wall.thickness, nu = s.wall.poisson;
    const double gs_over_b = 6.0 * (1.0 - nu) / (a * a);
    e.bending = viscosity * kBendingConstant * gs_over_b * ca * dx * dx * dx;
  }
  const double rate = s.flow.gradient.norm();
  e.flow = rate > 0 ? kFlowCap / rate : std::numeric_limits<double>::infinity();
  return e;
}

double analytic_spectral_radius(const Scene& s, double min_edge) { return 2.0 / stability_estimate(s, min_edge).limit(); }

}  // namespace capsflow
