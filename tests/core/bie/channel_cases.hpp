#pragma once
// Closed channels with exact solutions for the fixed wall's solve (bie/fixed_wall.hpp), shared by
// tests/core/bie/test_fixed_wall.cpp and perf/bie/channel_wall.cpp (docs/channel.md §3.3):
//   outside_point_force — the flow of a point force outside the channel, given on the whole wall,
//                         recovered inside;
//   inside_point_force  — the pressure drop a point force inside adds, against the reciprocal theorem;
//   free_sphere_on_axis — a rigid sphere carried by Poiseuille's flow in a tube: its velocity;
//   full_traction_empty_channel — Poiseuille's flow solved for its whole traction (caps carrying the
//                         profile): the formulation docs/channel.md §3.1 measures and sets aside;
//   empty_constriction  — a constricted duct's flow: the flux through every section, and the narrow
//                         part's Poiseuille profile (docs/channel.md §3.5).
#include <chrono>
#include <cmath>

#include "capsflow/core/bie/fixed_wall.hpp"
#include "capsflow/core/bie/multi_surface_single_layer.hpp"
#include "capsflow/core/bie/quadrature.hpp"
#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/geometry/surface_set.hpp"
#include "capsflow/core/mesh/channel.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/rhs/channel_dynamics.hpp"
#include "capsflow/core/theory/poiseuille.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow::channel_cases {

// The options of every case's wall (a benchmark switches the edges' pressure off to compare).
inline FixedWallOptions wall_options;

inline Vec3 point_force_flow(const Vec3& x, const Vec3& xs, const Vec3& F) {
  return fmm::Stokeslet::scale() * stokeslet_apply(x - xs, F);
}

inline double poiseuille(const ChannelGeometry& g, double y, double z) {
  return g.shape == ChannelShape::Tube ? tube_poiseuille_velocity(std::hypot(y, z), g.radius, 1.0)
                                       : duct_poiseuille_velocity(y, z, g.radius, 1.0);
}

// Three cross-sections (x = −1, 0, 1) of points out to 0.8 of the radius.
inline Points interior_points() {
  Points p(0, 3);
  for (const double x : {-1.0, 0.0, 1.0})
    for (int i = 0; i <= 4; ++i)
      for (int k = 0; k < 6; ++k) {
        const double r = 0.2 * i, a = 0.3 + k * 3.14159265358979323846 / 3;
        p.conservativeResize(p.rows() + 1, 3);
        p.row(p.rows() - 1) << x, r * std::cos(a), r * std::sin(a);
      }
  return p;
}

struct CaseResult {
  double error = 0;  // the case's measure (each case says which)
  double value = 0, exact = 0;
  int iterations = 0;
  bool converged = false;
  long nodes = 0;
  double seconds = 0;
};

// Solves for the wall velocity uw and returns the largest error at interior_points() against
// `exact`, divided by `scale`.
template <class Exact>
CaseResult interior_error(const SurfaceMesh& wall_mesh, const Points& uw, const Exact& exact, double scale) {
  FixedWall wall(wall_mesh, uw, wall_options);
  const FixedWallSolve s = wall.solve();
  const Points p = interior_points();
  Points u;
  wall.velocity_at(p, u);
  CaseResult r{0, 0, 0, s.iterations, s.converged, static_cast<long>(wall_mesh.num_nodes()), s.seconds};
  for (Eigen::Index k = 0; k < p.rows(); ++k)
    r.error = std::max(r.error, (u.row(k).transpose() - exact(Vec3(p.row(k).transpose()))).norm() / scale);
  return r;
}

// Unit radius, length 6; the force (1, 0.5, −0.3) at (0.3, 1.6, 0.2), 0.6 outside the side. The
// largest velocity error at interior_points(), relative to the largest |u| on the wall.
inline CaseResult outside_point_force(ChannelShape shape, double h) {
  ChannelGeometry g;
  g.shape = shape, g.radius = 1, g.length = 6, g.element_size = h;
  const ChannelMesh c = make_channel_mesh(g);
  const Vec3 xs(0.3, 1.6, 0.2), F(1, 0.5, -0.3);
  const Eigen::Index n = c.mesh.num_nodes();
  Points uw(n, 3);
  double scale = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    uw.row(i) = point_force_flow(c.mesh.vertices.row(i).transpose(), xs, F).transpose();
    scale = std::max(scale, uw.row(i).norm());
  }
  return interior_error(c.mesh, uw, [&](const Vec3& p) { return point_force_flow(p, xs, F); }, scale);
}

// Unit radius, length 8; the force (1, 0.2, 0.1) at (0.2, 0.3, −0.1). The wall's velocity is zero
// and the force's own flow is what the wall must cancel: S[f] = −u_F. Far from the force the
// disturbance is a uniform pressure in each cap, read as −f·n averaged over the cap's nodes more
// than 1.5 element sizes from the rim (the P1 traction cannot turn with the normal at the rim).
// value = p_in − p_out, exact = −F·u_P(x_s)/Q (V = 1), error = relative difference.
inline CaseResult inside_point_force(ChannelShape shape, double h) {
  ChannelGeometry g;
  g.shape = shape, g.radius = 1, g.length = 8, g.element_size = h;
  const ChannelMesh c = make_channel_mesh(g);
  const Vec3 xs(0.2, 0.3, -0.1), F(1, 0.2, 0.1);
  const Eigen::Index n = c.mesh.num_nodes();
  Points induced(n, 3);
  for (Eigen::Index i = 0; i < n; ++i)
    induced.row(i) = -point_force_flow(c.mesh.vertices.row(i).transpose(), xs, F).transpose();
  FixedWall wall(c.mesh, Points::Zero(n, 3), wall_options);
  const FixedWallSolve s = wall.solve(&induced);
  CaseResult r;
  r.iterations = s.iterations, r.converged = s.converged, r.nodes = static_cast<long>(n), r.seconds = s.seconds;
  r.value = pressure_drop_from_caps(c, wall.traction());
  r.exact = -F.x() * poiseuille(g, xs.y(), xs.z()) / channel_cross_section_area(g);
  r.error = std::abs(r.value - r.exact) / std::abs(r.exact);
  return r;
}

// Unit radius, length 6, V = 1: the caps carry Poiseuille's profile, the side is at rest, and the
// solve is for the whole traction (pressure included). The largest velocity error at
// interior_points(), relative to V.
inline CaseResult full_traction_empty_channel(ChannelShape shape, double h) {
  ChannelGeometry g;
  g.shape = shape, g.radius = 1, g.length = 6, g.element_size = h;
  const ChannelMesh c = make_channel_mesh(g);
  const Eigen::Index n = c.mesh.num_nodes();
  Points uw = Points::Zero(n, 3);
  for (Eigen::Index i = 0; i < n; ++i)
    if (c.node_region[static_cast<std::size_t>(i)] != ChannelRegion::Side)
      uw(i, 0) = poiseuille(g, c.mesh.vertices(i, 1), c.mesh.vertices(i, 2));
  return interior_error(c.mesh, uw, [&](const Vec3& p) { return Vec3(poiseuille(g, p.y(), p.z()), 0, 0); }, 1.0);
}

// A free rigid sphere's velocity on a tube's axis, U/V = K_s/K_t with Bungay & Brenner's (J. Fluid
// Mech. 1973) uniformly valid resistance coefficients, as transcribed in Dechadilok & Deen (Ind.
// Eng. Chem. Res. 45, 2006): K = (9/4)π²√2 (1 − λ)^(−5/2) [1 + c1(1 − λ) + c2(1 − λ)²] + Σ_{k=0..4} c_{k+3} λ^k,
// λ = a/R. Read from public code, not from the papers (docs/channel.md §3.4: it agrees with
// Haberman & Sayre's 1958 reflection result to 0.13 % at λ ≤ 0.3, 0.9 % at 0.5).
inline double bungay_brenner_velocity(double ratio) {
  const double t[7] = {-73.0 / 60, 77293.0 / 50400, -22.5083, -5.6117, -0.3363, -1.216, 1.647};
  const double s[7] = {7.0 / 60, -2227.0 / 50400, 4.0180, -3.9788, -1.9215, 4.392, 5.006};
  auto K = [ratio](const double (&c)[7]) {
    const double e = 1 - ratio, pi = 3.14159265358979323846;
    double sum = 9.0 / 4 * pi * pi * std::sqrt(2.0) * std::pow(e, -2.5) * (1 + c[0] * e + c[1] * e * e);
    for (int k = 0; k < 5; ++k) sum += c[k + 2] * std::pow(ratio, k);
    return sum;
  };
  return K(s) / K(t);
}

// Haberman & Sayre's (1958) free sphere on a tube's axis, relative to the mean velocity:
// U/V = 2 (1 − (2/3)λ² − 0.20217 λ⁵)/(1 − 0.75851 λ⁵) (a reflection result, for small λ).
inline double haberman_sayre_velocity(double ratio) {
  return 2 * (1 - 2.0 / 3 * ratio * ratio - 0.20217 * std::pow(ratio, 5)) / (1 - 0.75851 * std::pow(ratio, 5));
}

struct SphereResult {
  double velocity_ratio = 0;      // U/V
  double pressure_drop_caps = 0;  // Δp⁺ R/(μV) from the caps' traction
  double pressure_drop_reciprocal = 0;  // Δp⁺ R/(μV) from the sphere's traction and u_P (reciprocal theorem)
  int iterations = 0;
  bool converged = false;
  long sphere_nodes = 0, wall_nodes = 0;
  double seconds = 0;
};

// A rigid sphere of unit radius (icosahedron subdivided `level` times) centred on the axis of a
// tube of radius R = 1/ratio and length 6R (wall elements R/8 unless given), V = 1, force- and
// torque-free. The flow outside the sphere is u = u_P + S[φ] + S[f] (φ on the sphere, the
// disturbance traction f on the wall, one MultiSurfaceSingleLayer over both), with the unknowns
// φ, f and the sphere's rigid motion (U, Ω):
//   on the sphere:  u_P(x) + S[φ, f](x) − U − Ω × x = 0,   on the wall:  S[φ, f](x) = 0,
//   ∫ φ dS = 0,  ∫ x × φ dS = 0,
// solved by GMRES, each surface's S[n] = 0 deflated as in fixed_wall.hpp.
inline SphereResult free_sphere_on_axis(double ratio, int level, double wall_size = 0) {
  const double R = 1 / ratio;
  ChannelGeometry g;
  g.radius = R, g.length = 6 * R, g.element_size = wall_size > 0 ? wall_size : R / 8;
  const ChannelMesh c = make_channel_mesh(g);
  const SurfaceMesh sphere = make_sphere_mesh(BaseSolid::Icosahedron, level);
  const SurfaceSet set({sphere, c.mesh});
  MultiSurfaceSingleLayer S(set);
  const Points& x = set.mesh().vertices;
  const Eigen::Index ns = sphere.num_nodes(), nw = c.mesh.num_nodes(), n = ns + nw, m = 3 * n + 6;
  const Eigen::VectorXd area = nodal_areas(set.mesh());
  const Points normal = nodal_normals(set.mesh());
  const double sphere_area = area.head(ns).sum(), wall_area = area.tail(nw).sum();
  Eigen::VectorXd weight(m);
  for (Eigen::Index i = 0; i < n; ++i) weight.segment<3>(3 * i).setConstant(area[i]);
  weight.tail(6).setConstant(sphere_area);
  Points q(n, 3), u(n, 3);
  auto apply = [&](const Eigen::VectorXd& v, Eigen::VectorXd& y, Eigen::VectorXd*, double) {
    for (Eigen::Index i = 0; i < n; ++i) q.row(i) = v.segment<3>(3 * i).transpose();
    S.apply(x, q, u);
    const Vec3 U = v.segment<3>(3 * n), W = v.segment<3>(3 * n + 3);
    double n_phi = 0, n_f = 0;
    Vec3 force = Vec3::Zero(), torque = Vec3::Zero();
    for (Eigen::Index i = 0; i < n; ++i) {
      const double nq = area[i] * normal.row(i).dot(q.row(i));
      if (i < ns) {
        n_phi += nq;
        force += area[i] * q.row(i).transpose();
        torque += area[i] * Vec3(x.row(i).transpose()).cross(q.row(i).transpose());
      } else {
        n_f += nq;
      }
    }
    y.resize(m);
    for (Eigen::Index i = 0; i < n; ++i) {
      Vec3 r = u.row(i).transpose() + (i < ns ? n_phi / sphere_area : n_f / wall_area) * normal.row(i).transpose();
      if (i < ns) r -= U + W.cross(x.row(i).transpose());
      y.segment<3>(3 * i) = r;
    }
    y.segment<3>(3 * n) = force / sphere_area;
    y.segment<3>(3 * n + 3) = torque / sphere_area;
    return 0.0;
  };
  Eigen::VectorXd b = Eigen::VectorXd::Zero(m), v = Eigen::VectorXd::Zero(m);
  for (Eigen::Index i = 0; i < ns; ++i) b(3 * i) = -tube_poiseuille_velocity(std::hypot(x(i, 1), x(i, 2)), R, 1.0);
  const double scale = std::sqrt((weight.array() * b.array().square()).sum());
  const auto start = std::chrono::steady_clock::now();
  const GmresResult r = gmres(apply, b, v, weight, scale, GmresOptions{1e-8, 100, 3000, 0});
  SphereResult out;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.iterations = r.iterations, out.converged = r.converged;
  out.sphere_nodes = static_cast<long>(ns), out.wall_nodes = static_cast<long>(nw);
  out.velocity_ratio = v(3 * n);
  // Δp⁺ from the caps (as inside_point_force) and from the reciprocal theorem, Q Δp⁺ = −∫ φ·u_P dS.
  double work = 0;
  for (Eigen::Index i = 0; i < ns; ++i)
    work += area[i] * v(3 * i) * tube_poiseuille_velocity(std::hypot(x(i, 1), x(i, 2)), R, 1.0);
  const Points wall_traction = Points::Map(v.data() + 3 * ns, nw, 3);
  out.pressure_drop_caps = pressure_drop_from_caps(c, wall_traction) * R;
  out.pressure_drop_reciprocal = -work / channel_cross_section_area(g) * R;
  return out;
}

struct ConstrictionFlow {
  double profile_error = 0;      // largest |u − u_narrow| in the narrow middle, over its centreline velocity
  double flux_wide = 0, flux_narrow = 0;  // ∫ u_x over a wide and the narrow middle cross-section
  int iterations = 0;
  long nodes = 0;
  double seconds = 0;
};

// Duct of half-width 1 narrowed to the square of half-width 0.5 over x in [−1.5, 1.5], tapers of
// 0.5, length 9; mean velocity 1 at the inlet (Q = 4).
inline ConstrictionFlow empty_constriction(double h) {
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
  FixedWall wall(c.mesh, uw, wall_options);
  const FixedWallSolve s = wall.solve(nullptr, 1.0);
  ConstrictionFlow out;
  out.iterations = s.iterations, out.seconds = s.seconds;
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

}  // namespace capsflow::channel_cases
