// The single-layer operator against independent oracles: an adaptive polar-coordinate quadrature
// of the singular element integrals, the classical Stokes solutions on the unit sphere, the
// exterior flow of a translating sphere, and direct summation (for the FMM back end).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/bie/off_surface.hpp"
#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/fmm/calibration.hpp"
#include "capsflow/fmm/direct_sum_mixed.hpp"
#include "capsflow/fmm/stokeslet.hpp"
#include "support/gauss_kronrod.hpp"

using namespace capsflow;
using capsflow::testing::gauss_kronrod;
using capsflow::testing::polar_parameter_integral;

namespace {

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

// ∫_e G(x0 − y) φ_k dS over a quadratic triangle written about x0, in polar coordinates (ρ, φ)
// of its parameter plane (ξ, η) = ρ(cos φ, sin φ): G(y − x0) ρ = G((y − x0)/ρ) is smooth, the
// ρ-integral is done by 24-point Gauss, the angle adaptively. Independent of the Duffy map and of
// the closed-form flat part used by the production code.
std::array<Mat3, 3> polar_reference_curved(const QuadraticTriangle& T) {
  return polar_parameter_integral(
      [&](double xi, double eta, double rho) { return Mat3(T.jacobian(xi, eta) * stokeslet_matrix(T.offset(xi, eta) / rho)); });
}

SurfaceMesh unit_sphere(int level) { return make_sphere_mesh(BaseSolid::Icosahedron, level); }

double max_row_norm(const Points& a) { return a.rowwise().norm().maxCoeff(); }

}  // namespace

TEST(SingularIntegral, ClosedFormMatchesAdaptivePolarQuadrature) {
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
  const GaussLegendre unused(1);
  for (const auto& T : tris)
    for (int v = 0; v < 3; ++v) {  // each vertex as the singular one
      const Vec3 &a = T[v], &b = T[(v + 1) % 3], &c = T[(v + 2) % 3];
      const auto exact = singular_element_integral(a, b, c);
      const auto ref = polar_reference(a, b, c);
      const double scale = ref[0].norm();
      for (int k = 0; k < 3; ++k)
        EXPECT_LT((exact[k] - ref[k]).norm(), 1e-10 * scale) << "hat " << k;  // issue floor: 1e-10
      // The hot-path vector form is the same closed form contracted with the load (round-off);
      // a flat element pushes no quadrature points.
      const Vec3 q0(0.3, -1, 2), q1(1, 0.5, -0.2), q2(-0.7, 0.1, 0.4);
      StokesletBatch batch;
      const Vec3 applied = singular_element_apply(batch, QuadraticTriangle::flat(a, b, c), q0, q1, q2, unused, unused);
      EXPECT_EQ(batch.size(), 0u);
      EXPECT_LT((applied - (exact[0] * q0 + exact[1] * q1 + exact[2] * q2)).norm(), 1e-13 * scale * q0.norm());
    }
}

// Curved (quadratic) singular elements: closed-form flat part + Duffy curvature correction with the
// production rules against the independent polar quadrature of the whole curved element.
TEST(SingularIntegral, CurvedElementMatchesAdaptivePolarQuadrature) {
  const SingleLayerOptions defaults;
  const GaussLegendre rule_v(defaults.singular_points), rule_u(defaults.singular_radial_points);
  std::vector<QuadraticTriangle> elems;
  // Patches of the unit sphere, edge ≈ 0.08 (level 4), 0.16 (level 3), 0.33 (level 2), 0.6
  // (stretched/obtuse), midpoints lifted with the exact normals as the production code does;
  // each vertex in turn is the singular one (3 elements per patch).
  const std::vector<std::array<Vec3, 3>> sph = {
      {Vec3(0, 0, 1), Vec3(0.08, 0, 1), Vec3(0.03, 0.07, 1)},
      {Vec3(0, 0, 1), Vec3(0.16, 0.01, 1), Vec3(0.07, 0.15, 1)},
      {Vec3(0.1, 0, 1), Vec3(0.4, 0.05, 1), Vec3(0.2, 0.3, 1)},
      {Vec3(-0.3, 0, 1), Vec3(0.3, 0, 1), Vec3(0.05, 0.12, 1)},
  };
  for (auto t : sph) {
    for (auto& p : t) p.normalize();
    for (int v = 0; v < 3; ++v) {
      const Vec3 &a = t[v], &b = t[(v + 1) % 3], &c = t[(v + 2) % 3];
      elems.emplace_back(a, b, c, hermite_edge_midpoint(a, b, a, b), hermite_edge_midpoint(b, c, b, c),
                         hermite_edge_midpoint(c, a, c, a));
    }
  }
  // A generic quadratic triangle (midpoints displaced off the chords by ~10 % of the edge).
  elems.emplace_back(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.3, 0.9, 0), Vec3(0.5, 0.02, 0.1), Vec3(0.65, 0.45, 0.08),
                     Vec3(0.15, 0.46, 0.12));
  // Relative accuracy required of the production rules (4 × 3 points) per patch size. The
  // curvature correction is O(h) of the element integral, and the velocity on the unit sphere
  // changes by < 1e-3 of its discretisation error between these rules and 8 × 6 points
  // (bie_bench --singular-points/--singular-radial-points, perf/RESULTS.md §2.1).
  const double tol_production[5] = {1e-8, 1e-8, 1e-7, 1e-4, 1e-4};  // 0.08, 0.16, 0.33, 0.6, generic
  const GaussLegendre rule_v_tight(8), rule_u_tight(6);  // the same scheme, 8 × 6 points: the 1e-10
  for (size_t i = 0; i < elems.size(); ++i) {
    const auto& T = elems[i];
    const auto duffy = singular_element_integral(T, rule_v, rule_u);
    const auto tight = singular_element_integral(T, rule_v_tight, rule_u_tight);
    const auto ref = polar_reference_curved(T);
    const double scale = ref[0].norm();
    for (int k = 0; k < 3; ++k) {
      EXPECT_LT((duffy[k] - ref[k]).norm(), tol_production[i / 3] * scale) << "element " << i << " hat " << k;
      if (i < 9) {  // sphere patches up to 0.33
        EXPECT_LT((tight[k] - ref[k]).norm(), 1e-10 * scale) << "element " << i << " hat " << k;
      }
    }
    const Vec3 q0(0.3, -1, 2), q1(1, 0.5, -0.2), q2(-0.7, 0.1, 0.4);
    StokesletBatch batch;
    Vec3 applied = singular_element_apply(batch, T, q0, q1, q2, rule_v, rule_u);
    applied += batch.sum();  // after the call: the call fills the batch
    EXPECT_LT((applied - (duffy[0] * q0 + duffy[1] * q1 + duffy[2] * q2)).norm(), 1e-13 * scale * q0.norm());
  }
}

// Classical single-layer results on the unit sphere (μ = 1): uniform load c → 2c/3; load ω × n →
// rigid rotation (1/3) ω × x; uniform normal load → 0. Errors (max over nodes) at levels 3, 4, 5.
std::array<std::array<double, 3>, 3> sphere_errors(SurfaceGeometry geometry) {
  const Vec3 c(0.3, -1.0, 0.5), omega(0.2, 0.7, -0.4);
  std::array<std::array<double, 3>, 3> err{};
  for (int level = 3; level <= 5; ++level) {
    const SurfaceMesh m = unit_sphere(level);
    SingleLayerOptions opt;
    opt.backend = BackendRequest::Direct;
    opt.geometry = geometry;
    SingleLayer S(m.triangles, m.num_nodes(), opt);
    const Points& x = m.vertices;  // nodes on the sphere: n = x
    Points q_uni(x.rows(), 3), q_rot(x.rows(), 3), q_nrm = x, u;
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      q_uni.row(i) = c.transpose();
      q_rot.row(i) = omega.cross(Vec3(x.row(i))).transpose();
    }
    auto& e = err[static_cast<size_t>(level - 3)];
    S.apply(x, q_uni, u);
    e[0] = max_row_norm(u.rowwise() - (2.0 / 3.0) * c.transpose()) / ((2.0 / 3.0) * c.norm());
    S.apply(x, q_rot, u);
    Points rot(x.rows(), 3);
    for (Eigen::Index i = 0; i < x.rows(); ++i) rot.row(i) = (omega.cross(Vec3(x.row(i))) / 3.0).transpose();
    e[1] = max_row_norm(u - rot) / (omega.norm() / 3.0);
    S.apply(x, q_nrm, u);
    e[2] = max_row_norm(u) / (2.0 / 3.0);  // relative to the velocity of a unit uniform load
  }
  return err;
}

void expect_floors(const std::array<std::array<double, 3>, 3>& err, const double (&floor4)[3], const double (&min_order)[3]) {
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(err[1][k], floor4[k]) << "case " << k << " (level 4)";
    for (int l = 1; l < 3; ++l) {
      const double order = std::log2(err[l - 1][k] / err[l][k]);
      EXPECT_GE(order, min_order[k]) << "case " << k << " levels " << l + 2 << "→" << l + 3 << " errors " << err[l - 1][k]
                                     << " → " << err[l][k];
    }
  }
}

// Flat facets (the paper's discretisation). Two issue floors are relaxed here, because the flat
// geometry itself cannot meet them: integrating every element of the same polyhedron exactly
// (scratch run, perf/RESULTS.md §2.1) gives 1.63e-3 at level 4 for the rotation case (floor
// 1.5e-3) and an order of 1.79 between levels 4 and 5 for the normal load (floor 1.8).
const std::array<std::array<double, 3>, 3>& flat_sphere_errors() {
  static const auto err = sphere_errors(SurfaceGeometry::Flat);  // shared by the two tests below
  return err;
}

TEST(SingleLayerSphere, FlatFacetsConvergeAtSecondOrder) {
  const auto& err = flat_sphere_errors();
  expect_floors(err, {1.5e-3, 1.7e-3, 1.5e-3}, {1.8, 1.8, 1.7});
}

// Curved (quadratic, normal-lifted) elements: the floors as written — below 1.5e-3 at
// level 4 and order >= 1.8 between levels 3, 4, 5 for all three loads.
TEST(SingleLayerSphere, CurvedElementsMeetTheFloors) {
  const auto err = sphere_errors(SurfaceGeometry::Curved);
  expect_floors(err, {1.5e-3, 1.5e-3, 1.5e-3}, {1.8, 1.8, 1.8});
  // The curved geometry must be worth its cost: at least 10× more accurate than flat facets for
  // the uniform and normal loads at level 4, and 2× for the rotation (whose P1 load interpolation
  // error remains O(h²)).
  const auto& flat = flat_sphere_errors();
  EXPECT_LT(10 * err[1][0], flat[1][0]);
  EXPECT_LT(2 * err[1][1], flat[1][1]);
  EXPECT_LT(10 * err[1][2], flat[1][2]);
}

// The discrete operator against the exact integral over the same flat-facet surface (every
// element integrated by the refined rule, the touching ones by the independent polar rule):
// isolates the quadrature error from the geometric one. Levels 3 and 4, every 7th node.
TEST(SingleLayerSphere, MatchesExactFlatFacetIntegral) {
  for (int level : {3, 4}) {
    const SurfaceMesh m = unit_sphere(level);
    const Points& x = m.vertices;
    Points q(x.rows(), 3);
    for (Eigen::Index i = 0; i < x.rows(); ++i) q.row(i) << std::sin(2 * x(i, 0)) + 0.3, x(i, 1) * x(i, 2), std::cos(x(i, 2));
    // The default operator (edge-midpoint far field), and the one it replaced: the 3-point rule on
    // every element beyond the ring (corrected layers covering the whole sphere).
    SingleLayerOptions opt, gauss;
    opt.backend = gauss.backend = BackendRequest::Direct;
    gauss.corrected_layers = 1000;
    SingleLayer S(m.triangles, m.num_nodes(), opt), G(m.triangles, m.num_nodes(), gauss);
    Points u, ug;
    S.apply(x, q, u);
    G.apply(x, q, ug);
    double worst = 0, worst_gauss = 0;
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
          // 7-point rule on 4^depth parts, each part at least ~8 of its sizes away (relative error
          // per element < 1e-7, far below the 1e-6–1e-5 measured here).
          const Vec3 c = (x.row(t[0]) + x.row(t[1]) + x.row(t[2])).transpose() / 3.0;
          const double ratio = (x.row(i).transpose() - c).norm() / (x.row(t[0]) - x.row(t[1])).norm();
          const int depth = ratio < 3 ? 3 : (ratio < 10 ? 1 : 0);
          const auto R = refined_element_integral(x.row(i).transpose(), x.row(t[0]).transpose(), x.row(t[1]).transpose(),
                                                  x.row(t[2]).transpose(), depth);
          for (int k = 0; k < 3; ++k) ref += R[k] * q.row(t[k]).transpose();
        }
      }
      worst = std::max(worst, (u.row(i).transpose() - ref / (8 * M_PI)).norm());
      worst_gauss = std::max(worst_gauss, (ug.row(i).transpose() - ref / (8 * M_PI)).norm());
    }
    worst /= max_row_norm(u), worst_gauss /= max_row_norm(u);
    // A planning prototype measured (docs/boundary-integral.md §4.4) 7.7e-5 (relative) for Duffy +
    // 3-point far field at level 3; the refined near ring must do better than that bound.
    EXPECT_LT(worst, 7.7e-5) << "level " << level;
    // The edge-midpoint far field (3N sources) must be as accurate as the 3-point one (6N) it
    // replaced: within 1.5× of it (its error is 0.6–1.1× at levels 3–5 on random nodes,
    // docs/boundary-integral.md §4.2.1; 1.5 leaves room for the node sample).
    EXPECT_LT(worst, 1.5 * worst_gauss) << "level " << level << ": " << worst << " against " << worst_gauss;
    EXPECT_EQ(S.far_field_sources() * 2, 3 * m.num_elements());
    std::printf("level %d: quadrature error %.3g (edge midpoints), %.3g (Gauss points)\n", level, worst, worst_gauss);
    RecordProperty("quadrature_error_level" + std::to_string(level), std::to_string(worst));
    RecordProperty("quadrature_error_gauss_level" + std::to_string(level), std::to_string(worst_gauss));
  }
}

TEST(SingleLayerSphere, ExteriorOfTranslatingSphere) {
  const SurfaceMesh m = unit_sphere(4);
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
  // Faceted geometry: O(h²) ≈ 1e-3 at level 4 (docs/boundary-integral.md §4.4), times 2 near the surface.
  // Curved elements: the on-surface error at level 4 is ~5e-6 (CurvedElementsMeetTheFloors); off
  // the surface the adaptive near rule and the 3-point far field add O(h) quadrature error, so 1e-4.
  for (const auto& [geometry, tol] : {std::pair<SurfaceGeometry, double>{SurfaceGeometry::Flat, 2e-3}, {SurfaceGeometry::Curved, 1e-4}}) {
    SingleLayerOptions opt;
    opt.backend = BackendRequest::Direct;
    opt.geometry = geometry;
    SingleLayer S(m.triangles, m.num_nodes(), opt);
    Points u;
    OffSurfaceReport rep;
    evaluate_off_surface(S, m.vertices, q, targets, u, &rep);
    EXPECT_GE(rep.refined, 20);  // all targets at r = 1.02 (0.2 element sizes) use the adaptive rule
    EXPECT_EQ(rep.too_close, 0);
    for (int t = 0; t < 60; ++t) {
      const Vec3 ex = exact(targets.row(t).transpose());
      EXPECT_LT((u.row(t).transpose() - ex).norm(), tol * (2.0 / 3.0) * c.norm())
          << to_string(geometry) << " target " << t << " r " << targets.row(t).norm();
    }
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
    od.backend = BackendRequest::Direct;
    of.backend = BackendRequest::Fmm;
    of.tolerance = tol;
    SingleLayer D(m.triangles, m.num_nodes(), od), F(m.triangles, m.num_nodes(), of);
    Points ud, uf;
    D.apply(m.vertices, q, ud);
    F.apply(m.vertices, q, uf);
    const double rel = max_row_norm(uf - ud) / max_row_norm(ud);
    EXPECT_LT(rel, tol) << "FMM order " << F.fmm_order();  // issue: agree to the requested tolerance relative to max |v|
  }
  // From tolerance 1e-5 the direct back end sums single-precision pairs: it must honour the
  // tolerance as well (against the double-precision direct sum at the default 1e-6).
  SingleLayerOptions od, om;
  od.backend = om.backend = BackendRequest::Direct;
  om.tolerance = 1e-5;
  SingleLayer D(m.triangles, m.num_nodes(), od), M(m.triangles, m.num_nodes(), om);
  EXPECT_EQ(D.backend_reason().find("single precision"), std::string::npos);
  if (fmm::kMixedPrecisionDirectSum) {
    EXPECT_NE(M.backend_reason().find("single precision"), std::string::npos);
  }
  Points ud, um;
  D.apply(m.vertices, q, ud);
  M.apply(m.vertices, q, um);
  const double rel = max_row_norm(um - ud) / max_row_norm(ud);
  EXPECT_LT(rel, 1e-5);
}

// fmm_tolerance (fluid.tolerance = "auto"): the FMM back end promises it instead of `tolerance`, at
// the order it calls for; the direct back end ignores it (same sums, bit for bit).
TEST(SingleLayerBackends, TheFmmToleranceLoosensOnlyTheFmm) {
  SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 4);
  for (Eigen::Index i = 0; i < m.num_nodes(); ++i) {
    const Vec3 x = m.vertices.row(i);
    m.vertices.row(i) = Vec3(1.3 * x[0] + 0.1 * x[1] * x[2], 0.9 * x[1], 0.8 * x[2] + 0.1 * std::sin(2 * x[0])).transpose();
  }
  Points q(m.num_nodes(), 3);
  for (Eigen::Index i = 0; i < m.num_nodes(); ++i) {
    const Vec3 x = m.vertices.row(i);
    q.row(i) << std::cos(2 * x[1]) + x[0], x[2] * x[0], std::exp(0.2 * x[0]) - x[2];
  }
  SingleLayerOptions od, tight, loose;
  od.backend = BackendRequest::Direct;
  tight.backend = loose.backend = BackendRequest::Fmm;
  tight.fmm_leaf_size = loose.fmm_leaf_size = 64;  // a tree deep enough that the far field is approximated
  loose.fmm_tolerance = 1e-5;
  SingleLayer D(m.triangles, m.num_nodes(), od), T(m.triangles, m.num_nodes(), tight), L(m.triangles, m.num_nodes(), loose);
  EXPECT_EQ(T.far_field_tolerance(), 1e-6);
  EXPECT_EQ(L.far_field_tolerance(), 1e-5);
  EXPECT_EQ(L.fmm_order(), fmm::order_for_tolerance<fmm::Stokeslet>(kFmmToleranceMargin * 1e-5));
  EXPECT_LT(L.fmm_order(), T.fmm_order());  // the loosening takes effect (p 8 against 9)
  EXPECT_NE(L.backend_reason().find("the FMM at tolerance 1e-05"), std::string::npos) << L.backend_reason();
  // from 1e-5 the FMM's direct near field takes single-precision pairs (where the build has them)
  EXPECT_EQ(L.backend_reason().find("single-precision pairs") != std::string::npos, fmm::kMixedPrecisionDirectSum)
      << L.backend_reason();
  EXPECT_EQ(T.backend_reason().find("single-precision pairs"), std::string::npos) << T.backend_reason();
  Points ud, ut, ul;
  D.apply(m.vertices, q, ud);
  T.apply(m.vertices, q, ut);
  L.apply(m.vertices, q, ul);
  EXPECT_LT(max_row_norm(ul - ud) / max_row_norm(ud), 1e-5);  // the promise, relative to max |v|
  EXPECT_LT(max_row_norm(ut - ud) / max_row_norm(ud), 1e-6);
  // The direct back end: fmm_tolerance is not its promise, and changes nothing.
  SingleLayerOptions od2 = od;
  od2.fmm_tolerance = 1e-5;
  SingleLayer D2(m.triangles, m.num_nodes(), od2);
  EXPECT_EQ(D2.far_field_tolerance(), 1e-6);
  Points ud2;
  D2.apply(m.vertices, q, ud2);
  EXPECT_EQ(max_row_norm(ud2 - ud), 0.0);  // bit for bit
}
