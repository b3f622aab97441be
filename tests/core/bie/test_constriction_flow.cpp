// The empty constricted duct (mesh/channel.hpp, docs/channel.md §3.5): the inlet's Poiseuille flow
// u_P plus the wall's disturbance, which cancels u_P on the constriction's wall (the wall velocity
// −u_P). Against what must hold whatever the solver: the same flux Q through every cross-section
// (the wide one and the narrow one), and, in the middle of a narrow part long enough for the flow
// to develop, the square duct's Poiseuille profile at the mean velocity Q/(4 W_c²).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "capsflow/core/bie/fixed_wall.hpp"
#include "capsflow/core/bie/quadrature.hpp"
#include "capsflow/core/mesh/channel.hpp"
#include "capsflow/core/theory/poiseuille.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow {
namespace {

struct ConstrictionFlow {
  double profile_error = 0;      // largest |u − u_narrow| in the narrow middle, over its centreline velocity
  double flux_wide = 0, flux_narrow = 0;  // ∫ u_x over a wide and the narrow middle cross-section
  int iterations = 0;
  long nodes = 0;
};

// Duct of half-width 1 narrowed to the square of half-width 0.5 over x in [−1.5, 1.5], tapers of
// 0.5, length 9; mean velocity 1 at the inlet (Q = 4).
ConstrictionFlow empty_constriction(double h) {
  ChannelGeometry g;
  g.shape = ChannelShape::ConstrictedDuct, g.radius = 1, g.length = 9, g.element_size = h;
  g.constriction_height = 0.5, g.constriction_width = 0.5, g.constriction_length = 3, g.constriction_taper = 0.5;
  const ChannelMesh c = make_channel_mesh(g);
  auto u_p = [&](const Vec3& p) {
    return distance_from_axis(g, p.y(), p.z()) >= 1 ? 0.0 : duct_poiseuille_velocity(p.y(), p.z(), 1, 1);
  };
  Points uw = Points::Zero(c.mesh.num_nodes(), 3);
  for (Eigen::Index i = 0; i < uw.rows(); ++i)  // the side only: on the caps the disturbance vanishes
    if (c.node_region[static_cast<std::size_t>(i)] == ChannelRegion::Side) uw(i, 0) = -u_p(c.mesh.vertices.row(i).transpose());
  FixedWall wall(c.mesh, uw);
  const FixedWallSolve s = wall.solve(nullptr, 1.0);
  ConstrictionFlow out;
  std::printf("converged %d residual %.2e\n", s.converged, s.residual);
  {
    Points p(6, 3), u;
    p << -3.25, 0, 0, -3.25, 0.5, 0.5, 0, 0, 0, 0, 0.25, 0.25, -2, 0, 0, -1.75, 0, 0;
    wall.velocity_at(p, u);
    for (int k = 0; k < 6; ++k) std::printf("p %g %g %g: u_d %g %g %g  u_P %g\n", p(k,0), p(k,1), p(k,2), u(k,0), u(k,1), u(k,2), u_p(p.row(k).transpose()));
  }
  out.iterations = s.iterations;
  out.nodes = static_cast<long>(c.mesh.num_nodes());
  // Cross-sections by 10 × 10 Gauss–Legendre points; the profile at the narrow one's.
  const GaussLegendre rule(10);
  auto flux = [&](double x, double half, bool check_profile) {
    Points p(100, 3);
    for (int a = 0; a < 10; ++a)
      for (int b = 0; b < 10; ++b) p.row(10 * a + b) << x, half * (2 * rule.x[a] - 1), half * (2 * rule.x[b] - 1);  // the rule is on [0, 1]
    Points u;
    wall.velocity_at(p, u);
    double q = 0;
    const double narrow_mean = 4 / (4 * half * half), centreline = 2.0962 * narrow_mean;
    for (int a = 0; a < 10; ++a)
      for (int b = 0; b < 10; ++b) {
        const Vec3 pk = p.row(10 * a + b).transpose();
        const double ux = u(10 * a + b, 0) + u_p(pk);
        q += 4 * half * half * rule.w[a] * rule.w[b] * ux;
        if (check_profile) {
          const Vec3 exact(duct_poiseuille_velocity(pk.y(), pk.z(), half, narrow_mean), 0, 0);
          const Vec3 got(ux, u(10 * a + b, 1), u(10 * a + b, 2));
          out.profile_error = std::max(out.profile_error, (got - exact).norm() / centreline);
        }
      }
    return q;
  };
  out.flux_wide = flux(-3.25, 1.0, false);
  out.flux_narrow = flux(0, 0.5, true);
  return out;
}

TEST(ConstrictionFlow, PointForceDebug) {
  ChannelGeometry g;
  g.shape = ChannelShape::ConstrictedDuct, g.radius = 1, g.length = 9, g.element_size = 0.2;
  g.constriction_height = 0.5, g.constriction_width = 0.5, g.constriction_length = 3, g.constriction_taper = 0.5;
  const ChannelMesh c = make_channel_mesh(g);
  const Vec3 xs(0.3, 1.6, 0.2), F(1, 0.5, -0.3);
  auto flow = [&](const Vec3& x) { return Vec3(fmm::Stokeslet::scale() * stokeslet_apply(x - xs, F)); };
  Points uw(c.mesh.num_nodes(), 3);
  for (Eigen::Index i = 0; i < uw.rows(); ++i) uw.row(i) = flow(c.mesh.vertices.row(i).transpose()).transpose();
  FixedWall wall(c.mesh, uw);
  const FixedWallSolve s = wall.solve();
  Points p(4, 3), u;
  p << -3, 0, 0, -1, 0.1, 0.2, 0, 0.2, -0.2, 3, 0.5, 0;
  wall.velocity_at(p, u);
  for (int k = 0; k < 4; ++k) std::printf("pf %d: got %g %g %g exact %g %g %g\n", k, u(k,0), u(k,1), u(k,2), flow(p.row(k).transpose()).x(), flow(p.row(k).transpose()).y(), flow(p.row(k).transpose()).z());
  std::printf("it %d\n", s.iterations);
}

TEST(ConstrictionFlow, FluxIsConservedAndTheNarrowPartCarriesItsOwnPoiseuilleFlow) {
  for (const double h : {0.2, 0.14}) {
    const ConstrictionFlow f = empty_constriction(h);
    std::printf("h %.3f nodes %ld iterations %d profile %.3e flux wide %.6f narrow %.6f\n", h, f.nodes, f.iterations,
                f.profile_error, f.flux_wide, f.flux_narrow);
  }
}

}  // namespace
}  // namespace capsflow
