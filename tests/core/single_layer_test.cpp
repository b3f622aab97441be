// The single-layer operator against independent oracles: an adaptive polar-coordinate quadrature
// of the singular element integrals, the classical Stokes solutions on the unit sphere, the
// exterior flow of a translating sphere, and direct summation (for the FMM back end).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "capsflow/core/geometry.hpp"
#include "capsflow/core/mesh_generation.hpp"
#include "capsflow/core/single_layer.hpp"

using namespace capsflow;
constexpr int kDuffyPoints = 16;  // the production default (SingleLayerOptions::singular_points)

namespace {

// Adaptive Gauss–Kronrod (7–15) of a matrix-valued function on [a, b] to absolute tolerance.
using MatFn = std::function<Eigen::Matrix<double, 3, 9>(double)>;
Eigen::Matrix<double, 3, 9> gauss_kronrod(const MatFn& f, double a, double b, double tol, int depth = 0) {
  static const double xk[8] = {0.991455371120812639, 0.949107912342758525, 0.864864423359769073, 0.741531185599394440,
                               0.586087235467691130, 0.405845151377397167, 0.207784955007898468, 0.0};
  static const double wk[8] = {0.022935322010529225, 0.063092092629978553, 0.104790010322250184, 0.140653259715525919,
                               0.169004726639267903, 0.190350578064785410, 0.204432940075298892, 0.209482141084727828};
  static const double wg[4] = {0.129484966168869693, 0.279705391489276668, 0.381830050505118945, 0.417959183673469388};
  const double c = 0.5 * (a + b), h = 0.5 * (b - a);
  Eigen::Matrix<double, 3, 9> k = wk[7] * f(c), g = wg[3] * f(c);
  for (int i = 0; i < 7; ++i) {
    const auto fp = f(c + h * xk[i]), fm = f(c - h * xk[i]);
    k += wk[i] * (fp + fm);
    if (i % 2 == 1) g += wg[i / 2] * (fp + fm);
  }
  k *= h, g *= h;
  if ((k - g).cwiseAbs().maxCoeff() < tol || depth > 30) return k;
  return gauss_kronrod(f, a, c, tol / 2, depth + 1) + gauss_kronrod(f, c, b, tol / 2, depth + 1);
}

// ∫_e G(x0 − y) φ_k dS in polar coordinates (ρ, φ) about x0 in the element plane: ρ dρ cancels
// 1/ρ, the ρ-integral (polynomial) is done by 8-point Gauss, the angle adaptively.
std::array<Mat3, 3> polar_reference(const Vec3& x0, const Vec3& x1, const Vec3& x2) {
  const Vec3 e1 = (x1 - x0).normalized();
  const Vec3 nrm = (x1 - x0).cross(x2 - x0).normalized();
  const Vec3 e2 = nrm.cross(e1);
  const double phi2 = std::atan2((x2 - x0).dot(e2), (x2 - x0).dot(e1));
  const Eigen::Matrix<double, 2, 2> edge = (Eigen::Matrix<double, 2, 2>() << (x1 - x0).dot(e1), (x2 - x0).dot(e1),
                                            (x1 - x0).dot(e2), (x2 - x0).dot(e2)).finished();
  const Eigen::Matrix2d inv = edge.inverse();  // local plane coords -> (λ1, λ2)
  const GaussLegendre gl(8);
  auto f = [&](double phi) {
    const Eigen::Vector2d dir(std::cos(phi), std::sin(phi));
    // ρ_max: the ray hits the opposite edge where λ1 + λ2 = 1.
    const Eigen::Vector2d l = inv * dir;
    const double rmax = 1.0 / (l[0] + l[1]);
    const Vec3 d = std::cos(phi) * e1 + std::sin(phi) * e2;
    const Mat3 K = Mat3::Identity() + d * d.transpose();
    Eigen::Matrix<double, 3, 9> out = Eigen::Matrix<double, 3, 9>::Zero();
    for (size_t q = 0; q < gl.x.size(); ++q) {
      const double rho = gl.x[q] * rmax, w = gl.w[q] * rmax;
      const Eigen::Vector2d lam = inv * (rho * dir);
      const double phik[3] = {1 - lam[0] - lam[1], lam[0], lam[1]};
      for (int k = 0; k < 3; ++k) out.block<3, 3>(0, 3 * k) += w * phik[k] * K;
    }
    return out;
  };
  const auto I = gauss_kronrod(f, 0.0, phi2, 1e-14);
  return {I.block<3, 3>(0, 0), I.block<3, 3>(0, 3), I.block<3, 3>(0, 6)};
}

SurfaceMesh unit_sphere(int level) { return make_sphere_mesh(BaseSolid::Icosahedron, level); }

double max_row_norm(const Points& a) { return a.rowwise().norm().maxCoeff(); }

}  // namespace

TEST(SingularIntegral, DuffyMatchesAdaptivePolarQuadrature) {
  const GaussLegendre rule(kDuffyPoints);
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> U(-1, 1);
  // Regular, obtuse and stretched triangles (aspect up to ~6), as tank-treading produces.
  std::vector<std::array<Vec3, 3>> tris = {
      {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)},
      {Vec3(0.1, 0.2, 0.3), Vec3(0.2, 0.25, 0.3), Vec3(0.13, 0.3, 0.32)},
      {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 0.15, 0.05)},
      {Vec3(0, 0, 0), Vec3(0.2, 0.0, 0.0), Vec3(1.0, 0.3, 0.0)},
  };
  for (int t = 0; t < 4; ++t) tris.push_back({Vec3(U(gen), U(gen), U(gen)), Vec3(U(gen), U(gen), U(gen)), Vec3(U(gen), U(gen), U(gen))});
  for (const auto& T : tris)
    for (int v = 0; v < 3; ++v) {  // each vertex as the singular one
      const Vec3 &a = T[v], &b = T[(v + 1) % 3], &c = T[(v + 2) % 3];
      const auto duffy = singular_element_integral(a, b, c, rule);
      const auto ref = polar_reference(a, b, c);
      const double scale = ref[0].norm();
      for (int k = 0; k < 3; ++k)
        EXPECT_LT((duffy[k] - ref[k]).norm(), 1e-10 * scale) << "hat " << k;  // issue floor: 1e-10
      // The hot-path vector form is the same quadrature contracted with the load (round-off).
      const Vec3 q0(0.3, -1, 2), q1(1, 0.5, -0.2), q2(-0.7, 0.1, 0.4);
      const Vec3 applied = singular_element_apply(a, b, c, q0, q1, q2, rule);
      EXPECT_LT((applied - (duffy[0] * q0 + duffy[1] * q1 + duffy[2] * q2)).norm(), 1e-13 * scale * q0.norm());
    }
}

TEST(GaussLegendre, ExactForPolynomials) {
  for (int n : {1, 4, 16}) {
    const GaussLegendre g(n);
    double s = 0;
    for (size_t i = 0; i < g.x.size(); ++i) s += g.w[i] * std::pow(g.x[i], 2 * n - 1);
    EXPECT_NEAR(s, 1.0 / (2 * n), 1e-15);  // degree 2n−1 integrated exactly (round-off)
  }
}

// Classical single-layer results on the unit sphere (μ = 1): uniform load c → 2c/3; load ω × n →
// rigid rotation (1/3) ω × x; uniform normal load → 0. Second order under refinement.
TEST(SingleLayerSphere, AnalyticSolutionsConvergeAtSecondOrder) {
  const Vec3 c(0.3, -1.0, 0.5), omega(0.2, 0.7, -0.4);
  double prev[3] = {0, 0, 0};
  for (int level = 3; level <= 5; ++level) {
    const SurfaceMesh m = unit_sphere(level);
    SingleLayerOptions opt;
    opt.backend = "direct";
    SingleLayer S(m.triangles, m.num_nodes(), opt);
    const Points& x = m.vertices;  // nodes on the sphere: n = x
    Points q_uni(x.rows(), 3), q_rot(x.rows(), 3), q_nrm = x, u;
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      q_uni.row(i) = c.transpose();
      q_rot.row(i) = omega.cross(Vec3(x.row(i))).transpose();
    }
    double err[3];
    S.apply(x, q_uni, u);
    err[0] = max_row_norm(u.rowwise() - (2.0 / 3.0) * c.transpose()) / ((2.0 / 3.0) * c.norm());
    S.apply(x, q_rot, u);
    Points rot(x.rows(), 3);
    for (Eigen::Index i = 0; i < x.rows(); ++i) rot.row(i) = (omega.cross(Vec3(x.row(i))) / 3.0).transpose();
    err[1] = max_row_norm(u - rot) / (omega.norm() / 3.0);
    S.apply(x, q_nrm, u);
    err[2] = max_row_norm(u) / (2.0 / 3.0);  // relative to the velocity of a unit uniform load
    // Level-4 floors. The rotation case is held to 1.7e-3, not 1.5e-3: integrating every element
    // of the flat-facet surface exactly (refined rule everywhere, scratch run) gives 1.63e-3 for
    // it, so the remaining error is the P1 geometry, not the quadrature (see perf/RESULTS.md).
    const double floor4[3] = {1.5e-3, 1.7e-3, 1.5e-3};
    // Orders: the exact flat-facet integral itself converges at 1.79 between levels 4 and 5 for
    // the normal load (pre-asymptotic geometry error), so that case is held to 1.7.
    const double min_order[3] = {1.8, 1.8, 1.7};
    for (int k = 0; k < 3; ++k) {
      if (level == 4) EXPECT_LT(err[k], floor4[k]) << "case " << k;
      if (level > 3) {
        const double order = std::log2(prev[k] / err[k]);
        EXPECT_GE(order, min_order[k]) << "case " << k << " level " << level << " err " << err[k];
      }
      prev[k] = err[k];
    }
    RecordProperty("level" + std::to_string(level), std::to_string(err[0]) + " " + std::to_string(err[1]) + " " + std::to_string(err[2]));
  }
}

// The discrete operator against the exact integral over the same flat-facet surface (every
// element integrated by the refined rule, the touching ones by the independent polar rule):
// isolates the quadrature error from the geometric one.
TEST(SingleLayerSphere, MatchesExactFlatFacetIntegral) {
  const SurfaceMesh m = unit_sphere(3);
  const Points& x = m.vertices;
  Points q(x.rows(), 3);
  for (Eigen::Index i = 0; i < x.rows(); ++i) q.row(i) << std::sin(2 * x(i, 0)) + 0.3, x(i, 1) * x(i, 2), std::cos(x(i, 2));
  SingleLayerOptions opt;
  opt.backend = "direct";
  SingleLayer S(m.triangles, m.num_nodes(), opt);
  Points u;
  S.apply(x, q, u);
  double worst = 0;
  for (Eigen::Index i = 0; i < x.rows(); i += 7) {
    Vec3 ref = Vec3::Zero();
    for (Eigen::Index e = 0; e < m.num_elements(); ++e) {
      int t[3] = {m.triangles(e, 0), m.triangles(e, 1), m.triangles(e, 2)};
      const int k0 = t[0] == i ? 0 : (t[1] == i ? 1 : (t[2] == i ? 2 : -1));
      if (k0 >= 0) {
        const int a = t[k0], b = t[(k0 + 1) % 3], c = t[(k0 + 2) % 3];
        const auto P = polar_reference(x.row(a).transpose(), x.row(b).transpose(), x.row(c).transpose());
        ref += P[0] * q.row(a).transpose() + P[1] * q.row(b).transpose() + P[2] * q.row(c).transpose();
      } else {
        const auto R = refined_element_integral(x.row(i).transpose(), x.row(t[0]).transpose(), x.row(t[1]).transpose(),
                                                x.row(t[2]).transpose(), 3);
        for (int k = 0; k < 3; ++k) ref += R[k] * q.row(t[k]).transpose();
      }
    }
    worst = std::max(worst, (u.row(i).transpose() - ref / (8 * M_PI)).norm());
  }
  // numerics.md §4.4 measured 7.7e-5 (relative) for Duffy + 3-point far field at level 3; the
  // refined near ring must do better than that bound.
  EXPECT_LT(worst / max_row_norm(u), 7.7e-5);
  RecordProperty("quadrature_error_level3", std::to_string(worst / max_row_norm(u)));
}

TEST(SingleLayerSphere, ExteriorOfTranslatingSphere) {
  const SurfaceMesh m = unit_sphere(4);
  SingleLayerOptions opt;
  opt.backend = "direct";
  SingleLayer S(m.triangles, m.num_nodes(), opt);
  const Vec3 c(0.4, -0.3, 1.0);
  Points q(m.num_nodes(), 3);
  q.rowwise() = c.transpose();
  // Exact exterior flow of the uniform-traction sphere (a = 1): Stokeslet of force 4πc plus a
  // potential dipole; equals 2c/3 on the surface.
  auto exact = [&](const Vec3& xx) {
    const double r = xx.norm();
    const Mat3 xxT = xx * xx.transpose();
    return Vec3(0.5 * (Mat3::Identity() / r + xxT / std::pow(r, 3)) * c +
                (1.0 / 6.0) * (Mat3::Identity() / std::pow(r, 3) - 3 * xxT / std::pow(r, 5)) * c);
  };
  std::mt19937 gen(3);
  std::normal_distribution<double> N;
  Points targets(60, 3);
  for (int t = 0; t < 60; ++t) {
    const Vec3 d = Vec3(N(gen), N(gen), N(gen)).normalized();
    const double r = t < 20 ? 1.02 : (t < 40 ? 1.3 : 3.0);  // near (refined), intermediate, far
    targets.row(t) = (r * d).transpose();
  }
  Points u;
  OffSurfaceReport rep;
  S.evaluate_at(m.vertices, q, targets, u, &rep);
  EXPECT_GE(rep.refined, 20);  // all targets at r = 1.02 (0.2 element sizes) use the adaptive rule
  EXPECT_EQ(rep.too_close, 0);
  for (int t = 0; t < 60; ++t) {
    const Vec3 ex = exact(targets.row(t).transpose());
    // Faceted geometry: O(h²) ≈ 1e-3 at level 4 (numerics.md §4.4), times 2 near the surface.
    EXPECT_LT((u.row(t).transpose() - ex).norm(), 2e-3 * (2.0 / 3.0) * c.norm()) << "target " << t << " r " << targets.row(t).norm();
  }
}

TEST(SingleLayerBackends, FmmAgreesWithDirectOnDeformedSurface) {
  SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 4);
  // A non-symmetric smooth deformation and a random smooth load.
  for (Eigen::Index i = 0; i < m.num_nodes(); ++i) {
    const Vec3 x = m.vertices.row(i);
    m.vertices.row(i) = Vec3(1.4 * x[0] + 0.2 * x[1] * x[1], 0.8 * x[1] + 0.1 * x[0] * x[2], 0.9 * x[2] + 0.15 * std::sin(3 * x[0])).transpose();
  }
  Points q(m.num_nodes(), 3);
  for (Eigen::Index i = 0; i < m.num_nodes(); ++i) {
    const Vec3 x = m.vertices.row(i);
    q.row(i) << std::sin(2 * x[0] + 1) + x[2], std::cos(3 * x[1]) * x[0], std::exp(0.3 * x[2]) - x[1] * x[1];
  }
  for (double tol : {1e-3, 1e-6}) {
    SingleLayerOptions od, of;
    od.backend = "direct";
    of.backend = "fmm";
    of.tolerance = tol;
    SingleLayer D(m.triangles, m.num_nodes(), od), F(m.triangles, m.num_nodes(), of);
    Points ud, uf;
    D.apply(m.vertices, q, ud);
    F.apply(m.vertices, q, uf);
    const double rel = max_row_norm(uf - ud) / max_row_norm(ud);
    EXPECT_LT(rel, tol) << "FMM order " << F.fmm_order();  // issue: agree to the requested tolerance relative to max |v|
  }
}

TEST(SingleLayerBackends, AutoReportsChoice) {
  const SurfaceMesh m = unit_sphere(2);
  SingleLayer S(m.triangles, m.num_nodes(), {});
  EXPECT_EQ(S.backend(), FarFieldBackend::Direct);  // 960 sources: far below any FMM crossover
  EXPECT_NE(S.backend_reason().find("below"), std::string::npos);
}
