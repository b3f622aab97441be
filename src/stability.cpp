#include "capsflow/core/stability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "capsflow/core/scene.hpp"

namespace capsflow {

double StabilityEstimate::limit() const { return std::min({membrane, bending, flow}); }

std::string StabilityEstimate::limiting() const {
  const double l = limit();
  return l == membrane ? "membrane" : (l == bending ? "bending" : "flow");
}

double area_to_shear_modulus_ratio(const Scene& s) {
  if (s.wall.law == "nh") return 3.0;
  if (s.wall.law == "skalak") return 1.0 + 2.0 * s.wall.skalak_c;
  return (1.0 + s.wall.poisson) / (1.0 - s.wall.poisson);  // generalized Hooke
}

StabilityEstimate stability_estimate(const Scene& s, double dx) {
  StabilityEstimate e;
  const double ca = s.flow.ca_s;
  e.membrane = kMembraneConstant / (1.0 + area_to_shear_modulus_ratio(s)) * ca * dx;
  e.bending = std::numeric_limits<double>::infinity();
  if (s.wall.model == "gsmb") {
    const double a = s.wall.thickness, nu = s.wall.poisson;
    const double gs_over_b = 6.0 * (1.0 - nu) / (a * a);
    e.bending = kBendingConstant * gs_over_b * ca * dx * dx * dx;
  }
  const double rate = s.flow.gradient.norm();
  e.flow = rate > 0 ? kFlowCap / rate : std::numeric_limits<double>::infinity();
  return e;
}

}  // namespace capsflow
