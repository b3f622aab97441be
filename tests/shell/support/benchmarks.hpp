#pragma once
// Classical shell benchmarks for the forward static mode (geometry, loads, boundary conditions).
// Each returns the computed reference-point value; the tests compare it with the published one.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "capsflow/shell/static_solver.hpp"
#include "test_meshes.hpp"

namespace capsflow::shell::testing {

/// consistent nodal loads of a uniform surface traction p (per reference area)
inline Points pressure_loads(const Mesh& m, const Vec3& p) {
  Points F = Points::Zero(m.X.rows(), 3);
  for (Eigen::Index e = 0; e < m.T.rows(); ++e) {
    const Vec3 a = m.X.row(m.T(e, 0)), b = m.X.row(m.T(e, 1)), c = m.X.row(m.T(e, 2));
    const double A = 0.5 * (b - a).cross(c - a).norm();
    for (int k = 0; k < 3; ++k) F.row(m.T(e, k)) += (A / 3.0) * p.transpose();
  }
  return F;
}

inline MembraneLaw hooke(double E, double nu, double h) { return make_law("gh", E * h / (2 * (1 + nu)), nu); }

/// Square plate L x L, thickness h, uniform pressure q, quarter model n x n; clamped or simply
/// supported (hard). Returns the centre deflection divided by the Kirchhoff value alpha q L^4 / D
/// (alpha = 0.00126532 clamped, 0.00406235 simply supported; Timoshenko & Woinowsky-Krieger).
inline double plate_center_ratio(bool clamped, double h_over_L, int n, int pattern = 0) {
  const double L = 1.0, E = 1e6, nu = 0.3, h = h_over_L * L, q = 1.0;
  Mesh m = plate(L / 2, L / 2, n, n, pattern);
  StaticShell s(m.X, m.T, Points(), hooke(E, nu, h), h, nu);
  const double eps = 1e-9 * L;
  for (Eigen::Index i = 0; i < m.X.rows(); ++i) {
    const double x = m.X(i, 0), y = m.X(i, 1);
    if (x < eps || y < eps) {
      for (int c = 0; c < 3; ++c) s.fix_translation(i, c);
      if (clamped) s.fix_rotations(i);
      if (x < eps) s.fix_rotation_about(i, Vec3::UnitX());
      if (y < eps) s.fix_rotation_about(i, Vec3::UnitY());
    }
    if (x > L / 2 - eps) { s.fix_translation(i, 0); s.fix_rotation_about(i, Vec3::UnitY()); }
    if (y > L / 2 - eps) { s.fix_translation(i, 1); s.fix_rotation_about(i, Vec3::UnitX()); }
  }
  s.set_forces(pressure_loads(m, Vec3(0, 0, -q)));
  s.solve_linear();
  const double D = E * h * h * h / (12 * (1 - nu * nu));
  const double alpha = clamped ? 0.00126532 : 0.00406235;
  const int c = static_cast<int>(m.X.rows()) - 1;  // node (L/2, L/2)
  return -s.displacement()(c, 2) / (alpha * q * L * L * L * L / D);
}

/// Scordelis-Lo roof (MacNeal & Harder 1985): R = 25, L = 50, 80 deg, t = 0.25, E = 4.32e8, nu = 0,
/// gravity 90 per area; rigid diaphragms at the curved ends, free straight edges. Quarter model
/// n x n. Returns the vertical displacement (downward positive) at the midpoint of a free edge
/// (reference 0.3024, MacNeal & Harder; 0.3086 with shear-deformable deep-shell theory).
inline double scordelis_lo(int n, int pattern = 0) {
  const double R = 25, L = 50, phi = 40.0 * M_PI / 180.0, t = 0.25, E = 4.32e8, nu = 0.0;
  Mesh m = plate(L / 2, phi, n, n, pattern);  // (x, theta)
  Points X(m.X.rows(), 3), D(m.X.rows(), 3);
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const double x = m.X(i, 0), th = m.X(i, 1);
    X.row(i) << x, R * std::sin(th), R * std::cos(th);
    D.row(i) << 0, std::sin(th), std::cos(th);
  }
  Mesh c{X, m.T};
  StaticShell s(X, m.T, D, hooke(E, nu, t), t, nu);
  const double eps = 1e-9;
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const double x = m.X(i, 0), th = m.X(i, 1);
    const Vec3 circ(0, std::cos(th), -std::sin(th));
    if (x < eps) { s.fix_translation(i, 0); s.fix_rotation_about(i, circ); }            // symmetry x = 0
    if (th < eps) { s.fix_translation(i, 1); s.fix_rotation_about(i, Vec3::UnitX()); }  // crown
    if (x > L / 2 - eps) { s.fix_translation(i, 1); s.fix_translation(i, 2); }          // diaphragm
  }
  s.set_forces(pressure_loads(c, Vec3(0, 0, -90.0)));
  s.solve_linear();
  // node x = 0, theta = phi: index n * (n + 1)
  return -s.displacement()(n * (n + 1), 2);
}

/// Pinched cylinder with rigid diaphragms (MacNeal & Harder): R = 300, L = 600, t = 3, E = 3e6,
/// nu = 0.3, two opposite radial loads P = 1 at mid-length. Octant model n x n. Returns the radial
/// displacement under the load (reference 1.8248e-5).
inline double pinched_cylinder(int n, int pattern = 0) {
  const double R = 300, L = 600, t = 3, E = 3e6, nu = 0.3, P = 1.0;
  Mesh m = plate(L / 2, M_PI / 2, n, n, pattern);
  Points X(m.X.rows(), 3), D(m.X.rows(), 3);
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const double x = m.X(i, 0), th = m.X(i, 1);
    X.row(i) << x, R * std::sin(th), R * std::cos(th);
    D.row(i) << 0, std::sin(th), std::cos(th);
  }
  StaticShell s(X, m.T, D, hooke(E, nu, t), t, nu);
  const double eps = 1e-9;
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const double x = m.X(i, 0), th = m.X(i, 1);
    const Vec3 circ(0, std::cos(th), -std::sin(th));
    if (x < eps) { s.fix_translation(i, 0); s.fix_rotation_about(i, circ); }
    if (th < eps) { s.fix_translation(i, 1); s.fix_rotation_about(i, Vec3::UnitX()); }
    if (th > M_PI / 2 - eps) { s.fix_translation(i, 2); s.fix_rotation_about(i, Vec3::UnitX()); }
    if (x > L / 2 - eps) { s.fix_translation(i, 1); s.fix_translation(i, 2); }
  }
  Points F = Points::Zero(X.rows(), 3);
  F(0, 2) = -P / 4;  // node x = 0, theta = 0 (top), quarter of the load by symmetry
  s.set_forces(F);
  s.solve_linear();
  return -s.displacement()(0, 2);
}

/// Pinched hemisphere (MacNeal & Harder): R = 10, t = 0.04, E = 6.825e7, nu = 0.3, four radial
/// loads of 2 alternating in sign at 90 deg on the equator. Quarter model (n x n in
/// (azimuth, polar angle)); with_hole: 18 deg polar opening (reference 0.094 at the load),
/// without hole: a quarter mesh reaching the pole (reference 0.0924).
inline double pinched_hemisphere(int n, bool with_hole, int pattern = 0) {
  const double R = 10, t = 0.04, E = 6.825e7, nu = 0.3, F0 = 2.0;
  const double th0 = with_hole ? 18.0 * M_PI / 180.0 : 0.0;
  // parameter grid (u = azimuth in [0, 90 deg], v in [0, 1] from the equator to the pole/hole)
  Mesh g = plate(M_PI / 2, 1.0, n, n, pattern);
  Points X(g.X.rows(), 3);
  std::vector<int> remap(g.X.rows());
  int cnt = 0;
  const double polar_end = M_PI / 2 - th0;  // latitude of the hole edge (or the pole)
  for (Eigen::Index i = 0; i < g.X.rows(); ++i) {
    const double u = g.X(i, 0), lat = g.X(i, 1) * polar_end;
    X.row(i) << R * std::cos(lat) * std::cos(u), R * std::cos(lat) * std::sin(u), R * std::sin(lat);
    remap[i] = static_cast<int>(i);
  }
  Mesh m{X, g.T};
  if (!with_hole) {  // merge the pole nodes (top row) into one and drop degenerate triangles
    const int top0 = n * (n + 1);
    for (int k = 0; k <= n; ++k) remap[top0 + k] = top0;
    std::vector<int> newid(X.rows(), -1);
    for (Eigen::Index i = 0; i < X.rows(); ++i)
      if (remap[i] == i) newid[i] = cnt++;
    Points Y(cnt, 3);
    for (Eigen::Index i = 0; i < X.rows(); ++i)
      if (newid[i] >= 0) Y.row(newid[i]) = X.row(i);
    std::vector<std::array<int, 3>> tris;
    for (Eigen::Index e = 0; e < g.T.rows(); ++e) {
      std::array<int, 3> t{newid[remap[g.T(e, 0)]], newid[remap[g.T(e, 1)]], newid[remap[g.T(e, 2)]]};
      if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) tris.push_back(t);
    }
    m.X = Y;
    m.T.resize(tris.size(), 3);
    for (size_t e = 0; e < tris.size(); ++e) m.T.row(e) << tris[e][0], tris[e][1], tris[e][2];
  }
  // orient outward
  for (Eigen::Index e = 0; e < m.T.rows(); ++e) {
    const Vec3 a = m.X.row(m.T(e, 0)), b = m.X.row(m.T(e, 1)), c = m.X.row(m.T(e, 2));
    if ((b - a).cross(c - a).dot(a + b + c) < 0) std::swap(m.T(e, 1), m.T(e, 2));
  }
  Points D = m.X / R;
  StaticShell s(m.X, m.T, D, hooke(E, nu, t), t, nu);
  const double eps = 1e-9;
  int nA = -1, nB = -1;
  for (Eigen::Index i = 0; i < m.X.rows(); ++i) {
    const Vec3 p = m.X.row(i);
    if (std::abs(p[1]) < eps) { s.fix_translation(i, 1); s.fix_rotation_about(i, Vec3::UnitX()); }  // y = 0 plane
    if (std::abs(p[0]) < eps) { s.fix_translation(i, 0); s.fix_rotation_about(i, Vec3::UnitY()); }  // x = 0 plane
    if (std::abs(p[2]) < eps && std::abs(p[1]) < eps) nA = static_cast<int>(i);
    if (std::abs(p[2]) < eps && std::abs(p[0]) < eps) nB = static_cast<int>(i);
  }
  // rigid-body mode along z is free in the hole case: fix z at one equator node? The loads are
  // self-equilibrated; MacNeal-Harder fix the vertical displacement at one point.
  s.fix_translation(nA, 2);
  Points F = Points::Zero(m.X.rows(), 3);
  F(nA, 0) = F0 / 2;    // outward along +x (half: the load point lies on a symmetry plane)
  F(nB, 1) = -F0 / 2;   // inward along -y
  s.set_forces(F);
  s.solve_linear();
  return s.displacement()(nA, 0);
}

}  // namespace capsflow::shell::testing

namespace capsflow::shell::testing {

/// Clamped strip along x (length L, width b) with the root x = 0 clamped.
inline StaticShell clamped_strip(const Mesh& m, double L, double E, double nu, double h) {
  StaticShell s(m.X, m.T, Points(), hooke(E, nu, h), h, nu);
  for (Eigen::Index i = 0; i < m.X.rows(); ++i)
    if (m.X(i, 0) < 1e-9 * L) {
      for (int c = 0; c < 3; ++c) s.fix_translation(i, c);
      s.fix_rotations(i);
    }
  (void)L;
  return s;
}

/// nodal shares of a uniform line quantity along the edge x = L (ny cells of the strip)
inline std::vector<std::pair<int, double>> end_edge_shares(const Mesh& m, double L, double b) {
  std::vector<std::pair<int, double>> out;
  std::vector<std::pair<double, int>> nodes;
  for (Eigen::Index i = 0; i < m.X.rows(); ++i)
    if (m.X(i, 0) > L - 1e-9 * L) nodes.emplace_back(m.X(i, 1), static_cast<int>(i));
  std::sort(nodes.begin(), nodes.end());
  for (size_t k = 0; k < nodes.size(); ++k) {
    double len = 0;
    if (k > 0) len += 0.5 * (nodes[k].first - nodes[k - 1].first);
    if (k + 1 < nodes.size()) len += 0.5 * (nodes[k + 1].first - nodes[k].first);
    out.emplace_back(nodes[k].second, len / b);
  }
  return out;
}

/// Euler-Bernoulli elastica of a cantilever under a vertical dead tip load P (shooting, RK4):
/// returns (tip deflection W, tip shortening -U). Exact inextensible beam theory.
inline std::pair<double, double> elastica_tip_load(double P, double EI, double L) {
  auto shoot = [&](double k0, double& W, double& U) {
    const int N = 4000;
    const double ds = L / N;
    double th = 0, k = k0, x = 0, z = 0;
    auto f = [&](double t, double kk, double out[4]) {
      out[0] = kk; out[1] = -(P / EI) * std::cos(t); out[2] = std::cos(t); out[3] = std::sin(t);
    };
    for (int i = 0; i < N; ++i) {
      double a[4], b2[4], c[4], d[4];
      f(th, k, a);
      f(th + 0.5 * ds * a[0], k + 0.5 * ds * a[1], b2);
      f(th + 0.5 * ds * b2[0], k + 0.5 * ds * b2[1], c);
      f(th + ds * c[0], k + ds * c[1], d);
      th += ds / 6 * (a[0] + 2 * b2[0] + 2 * c[0] + d[0]);
      k += ds / 6 * (a[1] + 2 * b2[1] + 2 * c[1] + d[1]);
      x += ds / 6 * (a[2] + 2 * b2[2] + 2 * c[2] + d[2]);
      z += ds / 6 * (a[3] + 2 * b2[3] + 2 * c[3] + d[3]);
    }
    W = z;
    U = L - x;
    return k;  // curvature at the tip: must vanish
  };
  double lo = 0, hi = P * L / EI, W = 0, U = 0;
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    (shoot(mid, W, U) > 0 ? hi : lo) = mid;
  }
  shoot(0.5 * (lo + hi), W, U);
  return {W, U};
}

/// Cantilever strip under an end moment M = f * 2 pi EI / L (rolls into a full circle at f = 1).
/// Returns per load step (f, computed tip (U, W), exact tip (U, W)).
struct RollupPoint { double f, U, W, U_exact, W_exact; int newton; };
inline std::vector<RollupPoint> cantilever_rollup(int nx, int ny, int steps) {
  const double L = 12, b = 1, h = 0.1, E = 1.2e6, nu = 0.0;
  const double EI = E * b * h * h * h / 12, Mmax = 2 * M_PI * EI / L;
  Mesh m = plate(L, b, nx, ny, 1);
  StaticShell s = clamped_strip(m, L, E, nu, h);
  Points Mn = Points::Zero(m.X.rows(), 3);
  int tip = -1;
  for (auto [i, share] : end_edge_shares(m, L, b)) {
    Mn(i, 1) = -Mmax * share;  // moment about -y curls the strip towards +z
    tip = i;
  }
  s.set_moments(Mn);
  std::vector<RollupPoint> out;
  StaticOptions opt;
  opt.max_newton = 40;
  s.solve(steps, opt, [&](const StaticStep& st) {
    const double phi = 2 * M_PI * st.load_factor, R = L / phi;
    const Points u = s.displacement();
    out.push_back({st.load_factor, u(tip, 0), u(tip, 2), R * std::sin(phi) - L, R * (1 - std::cos(phi)),
                   st.converged ? st.newton : -1});
  });
  return out;
}

/// Cantilever strip (L = 10, b = 1, h = 0.1, E = 1.2e6, nu = 0) under a vertical dead end force
/// up to P = 4 (Sze, Liu & Lo 2004). Returns per step (P, W, -U).
struct ShearPoint { double P, W, mU; int newton; };
inline std::vector<ShearPoint> cantilever_end_shear(int nx, int ny, int steps) {
  const double L = 10, b = 1, h = 0.1, E = 1.2e6, nu = 0.0, Pmax = 4.0;
  Mesh m = plate(L, b, nx, ny, 1);
  StaticShell s = clamped_strip(m, L, E, nu, h);
  Points F = Points::Zero(m.X.rows(), 3);
  int tip = -1;
  for (auto [i, share] : end_edge_shares(m, L, b)) {
    F(i, 2) = Pmax * share;
    tip = i;
  }
  s.set_forces(F);
  std::vector<ShearPoint> out;
  StaticOptions opt;
  opt.max_newton = 40;
  s.solve(steps, opt, [&](const StaticStep& st) {
    const Points u = s.displacement();
    out.push_back({Pmax * st.load_factor, u(tip, 2), -u(tip, 0), st.converged ? st.newton : -1});
  });
  return out;
}

/// Slit annular plate (Sze, Liu & Lo 2004): inner radius 6, outer 10, h = 0.03, E = 21e6, nu = 0,
/// clamped along one side of the slit, vertical dead line force up to 0.8 per unit length on the
/// other. Returns per step (load factor, W at the inner radius A, W at the outer radius B).
struct SlitPoint { double f, WA, WB; int newton; };
inline std::vector<SlitPoint> slit_annular_plate(int nr, int nt, int steps) {
  const double Ri = 6, Ro = 10, h = 0.03, E = 21e6, nu = 0.0, q = 0.8;
  Mesh g = plate(2 * M_PI, Ro - Ri, nt, nr, 1);  // (theta, r - Ri)
  Points X(g.X.rows(), 3);
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const double th = g.X(i, 0), r = Ri + g.X(i, 1);
    X.row(i) << r * std::cos(th), r * std::sin(th), 0.0;
  }
  StaticShell s(X, g.T, Points(), hooke(E, nu, h), h, nu);
  Points F = Points::Zero(X.rows(), 3);
  int A = -1, B = -1;
  const double dr = (Ro - Ri) / nr;
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const double th = g.X(i, 0), rr = g.X(i, 1);
    if (th < 1e-9) {
      for (int c = 0; c < 3; ++c) s.fix_translation(i, c);
      s.fix_rotations(i);
    }
    if (th > 2 * M_PI - 1e-9) {
      const bool end = rr < 1e-9 || rr > Ro - Ri - 1e-9;
      F(i, 2) = q * dr * (end ? 0.5 : 1.0);
      if (rr < 1e-9) A = static_cast<int>(i);
      if (rr > Ro - Ri - 1e-9) B = static_cast<int>(i);
    }
  }
  s.set_forces(F);
  std::vector<SlitPoint> out;
  StaticOptions opt;
  opt.max_newton = 40;
  s.solve(steps, opt, [&](const StaticStep& st) {
    const Points u = s.displacement();
    out.push_back({st.load_factor, u(A, 2), u(B, 2), st.converged ? st.newton : -1});
  });
  return out;
}

}  // namespace capsflow::shell::testing
