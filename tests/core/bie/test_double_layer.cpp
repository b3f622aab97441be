// The double-layer quadrature against independent oracles: an adaptive polar-coordinate
// quadrature of the singular (curved) element (docs/boundary-integral.md §4.7.2).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "capsflow/core/bie/double_layer.hpp"
#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/fmm/direct_sum_mixed.hpp"
#include "support/gauss_kronrod.hpp"

using namespace capsflow;
using capsflow::testing::polar_parameter_integral;

namespace {

// ∫_e T(x0 − y)·n φ_k dS over a quadratic triangle written about x0, in polar coordinates of its
// parameter plane: with y − x0 = ρ d(ρ, φ) and n dS = N ρ dρ dφ, the integrand times ρ is
// −T(d)·N/ρ = 6 (d·N) d dᵀ/(ρ |d|⁵), bounded because d·N = O(ρ). Independent of the Duffy map
// and of its sinh substitution.
std::array<Mat3, 3> polar_reference_double_layer(const QuadraticTriangle& T) {
  return polar_parameter_integral(
      [&](double xi, double eta, double rho) {
        const Vec3 d = T.offset(xi, eta) / rho, N = T.area_normal(xi, eta);
        return Mat3((6.0 * d.dot(N) / (rho * std::pow(d.norm(), 5))) * (d * d.transpose()));
      },
      1e-15);
}

// A patch of the unit sphere about x0 with edges of length ~h, as a curved element through its
// exact normals (the lift of the production code).
QuadraticTriangle sphere_element(double h, double skew) {
  const Vec3 x0 = Vec3(0.1, 0.2, 1).normalized();
  const Vec3 t1 = Vec3::UnitX().cross(x0).normalized(), t2 = x0.cross(t1);
  const Vec3 x1 = (x0 + h * t1).normalized(), x2 = (x0 + h * (skew * t1 + 0.9 * t2)).normalized();
  auto mid = [](const Vec3& a, const Vec3& b) { return hermite_edge_midpoint(a, b, a, b); };
  return QuadraticTriangle(x0, x1, x2, mid(x0, x1), mid(x1, x2), mid(x2, x0));
}

}  // namespace

TEST(SingularDoubleLayer, FlatFacetIsZero) {
  // r = x0 − y lies in the facet: T(r)·n = −6 (r·n) r rᵀ/|r|⁵ = 0 exactly.
  const GaussLegendre rv(4), ru(3);
  const auto M = singular_element_double_layer(QuadraticTriangle::flat(Vec3(0, 0, 0), Vec3(1, 0, 0.2), Vec3(0.1, 1, 0)), rv, ru);
  for (const auto& m : M) EXPECT_EQ(m.norm(), 0.0);
}

TEST(SingularDoubleLayer, CurvedElementMatchesAdaptivePolarQuadrature) {
  const GaussLegendre rule_v(4), rule_u(3), tight_v(8), tight_u(8);
  for (double h : {0.05, 0.1, 0.2, 0.4})
    for (double skew : {0.0, 0.5, -0.6}) {  // right-angled, acute, obtuse at x0
      const QuadraticTriangle T = sphere_element(h, skew);
      const auto ref = polar_reference_double_layer(T);
      const auto prod = singular_element_double_layer(T, rule_v, rule_u);
      const auto tight = singular_element_double_layer(T, tight_v, tight_u);
      const double scale = ref[0].norm() + ref[1].norm() + ref[2].norm();
      ASSERT_GT(scale, 0.0);
      for (int k = 0; k < 3; ++k) {
        // Tight 8 × 8 rule: measured ≤ 6e-13 on the right-angled and acute elements and ≤ 3.8e-10 on
        // the obtuse one (the near-edge peak at small d converges slower), against a reference
        // requested to 1e-15: 1e-9 bounds both. Production 4 × 3 rule: measured ≤ 1.4e-5 (obtuse),
        // ≤ 1.1e-6 otherwise; 5e-5 bounds it. The touching elements carry O(h) of the double layer
        // on curved surfaces (0 on flat facets), so 5e-5 of them is far below its O(h²) error.
        EXPECT_LT((tight[k] - ref[k]).norm(), 1e-9 * scale) << "h " << h << " skew " << skew << " hat " << k;
        EXPECT_LT((prod[k] - ref[k]).norm(), 5e-5 * scale) << "h " << h << " skew " << skew << " hat " << k;
      }
    }
}

namespace {

// Exact double layer on the unit sphere (docs/boundary-integral.md §4.7.4): every field below is
// an eigenfunction, D[u] = μ u. H is a solid harmonic of degree n.
//   rigid motions c and ω × x:        μ = 1/2
//   x × ∇H (toroidal):                μ = 3/(2(2n+1))
//   ∇H (interior potential flow):     μ = 3/(2(2n−1)(2n+1))
//   ∇(H r^−(2n+1)) = ∇H − (2n+1)H x:  μ = −3/(2(2n+1)(2n+3))   (n = 0: x, μ = −1/2)
struct SphereField {
  std::string name;
  std::function<Vec3(const Vec3&)> u;
  double mu;
};

std::vector<SphereField> sphere_fields() {
  const Vec3 c(0.3, -1.0, 0.5), omega(0.2, 0.7, -0.4);
  auto grad2 = [](const Vec3& x) { return Vec3(x.y(), x.x(), 0); };  // H = xy
  auto grad3 = [](const Vec3& x) { return Vec3(x.y() * x.z(), x.x() * x.z(), x.x() * x.y()); };  // H = xyz
  return {
      {"translation", [c](const Vec3&) { return c; }, 0.5},
      {"rotation", [omega](const Vec3& x) { return Vec3(omega.cross(x)); }, 0.5},
      {"toroidal n=2", [grad2](const Vec3& x) { return Vec3(x.cross(grad2(x))); }, 3.0 / 10},
      {"toroidal n=3", [grad3](const Vec3& x) { return Vec3(x.cross(grad3(x))); }, 3.0 / 14},
      {"interior n=2", grad2, 1.0 / 10},
      {"interior n=3", grad3, 3.0 / 70},
      {"exterior n=0", [](const Vec3& x) { return x; }, -0.5},
      {"exterior n=1", [](const Vec3& x) { return Vec3(Vec3::UnitZ() - 3 * x.z() * x); }, -1.0 / 10},
      {"exterior n=2", [grad2](const Vec3& x) { return Vec3(grad2(x) - 5 * x.x() * x.y() * x); }, -3.0 / 70},
      {"exterior n=3", [grad3](const Vec3& x) { return Vec3(grad3(x) - 7 * x.x() * x.y() * x.z() * x); }, -1.0 / 42},
  };
}

// Largest node error of D_h[u] against μ u, relative to max |u|, per field, at mesh levels 3–5.
std::vector<std::array<double, 3>> sphere_errors(SurfaceGeometry geometry) {
  const auto fields = sphere_fields();
  std::vector<std::array<double, 3>> err(fields.size());
  for (int level = 3; level <= 5; ++level) {
    const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, level);
    DoubleLayerOptions opt;
    opt.backend = BackendRequest::Direct;
    opt.geometry = geometry;
    DoubleLayer D(m.triangles, m.num_nodes(), opt);
    D.set_surface(m.vertices);
    for (size_t f = 0; f < fields.size(); ++f) {
      Points u(m.num_nodes(), 3), out;
      for (Eigen::Index i = 0; i < u.rows(); ++i) u.row(i) = fields[f].u(m.vertices.row(i).transpose()).transpose();
      D.apply(u, out);
      err[f][static_cast<size_t>(level - 3)] = (out - fields[f].mu * u).rowwise().norm().maxCoeff() / u.rowwise().norm().maxCoeff();
    }
  }
  for (size_t f = 0; f < fields.size(); ++f)
    std::printf("%-8s %-14s %.3e %.3e %.3e  orders %.2f %.2f\n", geometry == SurfaceGeometry::Flat ? "flat" : "curved",
                fields[f].name.c_str(), err[f][0], err[f][1], err[f][2], std::log2(err[f][0] / err[f][1]),
                std::log2(err[f][1] / err[f][2]));
  return err;
}

const std::vector<std::array<double, 3>>& flat_errors() {
  static const auto err = sphere_errors(SurfaceGeometry::Flat);  // shared by the two tests below
  return err;
}

}  // namespace

// Errors at level 4 (5 120 elements) and orders between levels 3, 4, 5 (docs/boundary-integral.md §4.7.4):
// second order for every non-rigid field on both geometries. The floors below are the measured
// worst cases with a margin: level-4 error 2.5e-3 (flat) and 9.0e-4 (curved), orders ≥ 1.92
// (floor 1.85).
void expect_second_order(const std::vector<std::array<double, 3>>& err, double floor4, size_t first) {
  const auto fields = sphere_fields();
  for (size_t f = first; f < err.size(); ++f) {
    EXPECT_LT(err[f][1], floor4) << fields[f].name;
    for (int l = 1; l < 3; ++l)
      EXPECT_GE(std::log2(err[f][static_cast<size_t>(l - 1)] / err[f][static_cast<size_t>(l)]), 1.85)
          << fields[f].name << " levels " << l + 2 << "→" << l + 3;
  }
}

TEST(DoubleLayerSphere, FlatFacetsConvergeAtSecondOrder) {
  const auto err = flat_errors();
  // Rigid motions are exact to round-off on flat facets: D_h[c] = c/2 is imposed, and for ω × x
  // every pair term vanishes after the subtraction, T(r)·(ω × r) = −6 r (r·(ω × r))(r·n)/|r|⁵ = 0.
  for (size_t f = 0; f < 2; ++f)
    for (double e : err[f]) EXPECT_LT(e, 1e-13) << sphere_fields()[f].name;
  expect_second_order(err, 3e-3, 2);
}

TEST(DoubleLayerSphere, CurvedElementsConvergeAtSecondOrder) {
  const auto err = sphere_errors(SurfaceGeometry::Curved);
  for (double e : err[0]) EXPECT_LT(e, 1e-13);  // constants: imposed
  // The rotation is not exact here: its P1 interpolation lives on the chords, not on the curved
  // surface (O(h²): 3.6e-4 at level 4); the toroidal fields likewise (2–3× the flat error).
  expect_second_order(err, 1e-3, 1);
  // Where the curved surface pays: the potential-flow (normal-carrying) modes, measured 6–14×
  // more accurate than on flat facets at level 4, 3.2× for the radial field x; at least 2.5×.
  const auto& flat = flat_errors();
  for (size_t f = 4; f < err.size(); ++f) EXPECT_LT(2.5 * err[f][1], flat[f][1]) << sphere_fields()[f].name;
}

namespace {

// The boundary-integral identities of §4.7.4 on any closed surface, for the flow of a point force
// F at x_s (u = G(x − x_s)F/8π, traction f = T(x − x_s)·F·n/8π):
//   x_s outside S (flow regular inside):  ½ u = S[f] + D[u]
//   x_s inside S (flow decaying outside): ½ u = −S[f] − D[u]
// Largest node residual relative to max |u|, at levels 3–5, for the single and double layers
// discretised alike.
std::array<double, 3> identity_residuals(double aspect, SurfaceGeometry geometry, const Vec3& xs) {
  const Vec3 F(0.3, -0.5, 0.8);
  const bool inside = xs.norm() < 0.5;
  std::array<double, 3> res{};
  for (int level = 3; level <= 5; ++level) {
    const SurfaceMesh sphere = make_sphere_mesh(BaseSolid::Icosahedron, level);
    SurfaceMesh m = sphere;
    map_to_spheroid(m, aspect, 2);
    SingleLayerOptions opt;
    opt.backend = BackendRequest::Direct;
    opt.geometry = geometry;
    DoubleLayerOptions dl_opt;
    static_cast<LayerOptions&>(dl_opt) = opt;  // the same far field and surface
    SingleLayer S(m.triangles, m.num_nodes(), opt);
    DoubleLayer D(m.triangles, m.num_nodes(), dl_opt);
    // Exact outward normals at the nodes: the unit sphere's nodes scaled by the semi-axes.
    Points u(m.num_nodes(), 3), f(m.num_nodes(), 3), Su, Du;
    Vec3 semi;
    for (int k = 0; k < 3; ++k) semi[k] = m.vertices.col(k).norm() / sphere.vertices.col(k).norm();
    for (Eigen::Index i = 0; i < u.rows(); ++i) {
      const Vec3 x = m.vertices.row(i).transpose(), r = x - xs;
      const Vec3 n = x.cwiseQuotient(semi.cwiseProduct(semi)).normalized();
      u.row(i) = (stokeslet_matrix(r) * F / (8 * M_PI)).transpose();
      const double r5 = std::pow(r.norm(), 5);
      f.row(i) = (-6.0 * r.dot(F) * r.dot(n) / r5 * r / (8 * M_PI)).transpose();
    }
    S.apply(m.vertices, f, Su);
    D.set_surface(m.vertices);
    D.apply(u, Du);
    const Points residual = inside ? Points(0.5 * u + Su + Du) : Points(0.5 * u - Su - Du);
    res[static_cast<size_t>(level - 3)] = residual.rowwise().norm().maxCoeff() / u.rowwise().norm().maxCoeff();
  }
  std::printf("identity aspect %.1f %-6s %s: %.3e %.3e %.3e orders %.2f %.2f\n", aspect,
              geometry == SurfaceGeometry::Flat ? "flat" : "curved", inside ? "inside " : "outside", res[0], res[1],
              res[2], std::log2(res[0] / res[1]), std::log2(res[1] / res[2]));
  return res;
}

}  // namespace

// A prolate spheroid (a/b = 2): no closed form for D alone, but the identities tie it to the
// single layer for any Stokes flow, here point forces outside and inside.
TEST(DoubleLayerSpheroid, ReproducesTheBoundaryIntegralIdentities) {
  for (SurfaceGeometry g : {SurfaceGeometry::Flat, SurfaceGeometry::Curved})
    for (const Vec3& xs : {Vec3(1.5, 0.4, 1.2), Vec3(0.1, -0.05, 0.3)}) {
      const auto r = identity_residuals(2.0, g, xs);
      // Measured at level 4: 9.9e-4–2.3e-3; orders 1.82–1.90 (levels 3→4) and 1.95–1.96 (4→5).
      EXPECT_LT(r[1], 3e-3);
      EXPECT_GE(std::log2(r[0] / r[1]), 1.75);
      EXPECT_GE(std::log2(r[1] / r[2]), 1.85);
    }
}

// The far field by the stresslet FMM (fluid.backend = "fmm") against the direct sum: the same
// operator up to the FMM's tolerance, the near field and the identity term untouched.
TEST(DoubleLayerSphere, FmmFarFieldMatchesTheDirectSum) {
  const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 4);
  const auto field = sphere_fields()[8];  // exterior n = 2: no symmetry that could hide an error
  Points u(m.num_nodes(), 3);
  for (Eigen::Index i = 0; i < u.rows(); ++i) u.row(i) = field.u(m.vertices.row(i).transpose()).transpose();
  Points out[2];
  for (int k = 0; k < 2; ++k) {
    DoubleLayerOptions opt;
    opt.backend = k == 0 ? BackendRequest::Direct : BackendRequest::Fmm;
    opt.tolerance = 1e-6;
    DoubleLayer D(m.triangles, m.num_nodes(), opt);
    ASSERT_EQ(D.backend(), k == 0 ? FarFieldBackend::Direct : FarFieldBackend::Fmm);
    D.set_surface(m.vertices);
    D.apply(u, out[k]);
  }
  const double diff = (out[1] - out[0]).rowwise().norm().maxCoeff() / out[0].rowwise().norm().maxCoeff();
  std::printf("double layer, level 4: FMM against direct, max relative difference %.2e\n", diff);
  // The FMM promises 1e-6 (asked for 2.5e-7 in its relative L2 norm, as for the single layer); the
  // identity term D̃[1] (three densities of one FMM evaluation) carries the same error.
  EXPECT_LT(diff, 1e-5);
  EXPECT_GT(diff, 0.0);  // the two sums did differ: the FMM path ran
}

namespace {
// The nodes of an icosphere stretched to an a/b = 2 prolate spheroid, and a smooth field on them
// with no symmetry that could hide an error.
Points spheroid_nodes(const SurfaceMesh& m) {
  Points x = m.vertices;
  x.col(2) *= 2.0;
  return x;
}
Points field_without_symmetry(const Points& x) {
  Points u(x.rows(), 3);
  for (Eigen::Index i = 0; i < x.rows(); ++i) u.row(i) << x(i, 1) - 0.3 * x(i, 2), x(i, 0) * x(i, 2), 1.0 + x(i, 0) * x(i, 0);
  return u;
}
}  // namespace

// set_surface(x, &u, &Du) — the set-up with its first application from the same far-field pass
// (the viscosity-ratio solve's initial residual) — against set_surface(x) then apply(u), on an
// a/b = 2 spheroid with a field of no symmetry, for both far-field back ends, and the operator
// applied afterwards to another field is unchanged by the fused call.
TEST(DoubleLayerSpheroid, SetUpWithItsFirstApplicationEqualsSetUpThenApply) {
  const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 3);
  const Points x = spheroid_nodes(m), u = field_without_symmetry(x);
  Points v(m.num_nodes(), 3);
  for (Eigen::Index i = 0; i < x.rows(); ++i) v.row(i) << std::sin(x(i, 0)), x(i, 1) * x(i, 1), -x(i, 2);
  for (BackendRequest b : {BackendRequest::Direct, BackendRequest::Fmm}) {
    DoubleLayerOptions opt;
    opt.backend = b;
    opt.tolerance = 1e-6;
    DoubleLayer A(m.triangles, m.num_nodes(), opt), B(m.triangles, m.num_nodes(), opt);
    Points Au, Bu, Av, Bv;
    A.set_surface(x);
    A.apply(u, Au);
    B.set_surface(x, &u, &Bu);
    A.apply(v, Av);
    B.apply(v, Bv);
    const double scale = Au.cwiseAbs().maxCoeff();
    // Same pairs summed in a different grouping (direct: one 9-output pass instead of a 6- and a
    // 3-output pass; FMM: one evaluation of 4 densities instead of 3 + 1): round-off only, ~1e-15
    // relative; 1e-12 leaves room for the FMM's different accumulation order.
    EXPECT_LT((Bu - Au).cwiseAbs().maxCoeff(), 1e-12 * scale) << to_string(b);
    EXPECT_LT((Bv - Av).cwiseAbs().maxCoeff(), 1e-12 * Av.cwiseAbs().maxCoeff()) << to_string(b);
    EXPECT_EQ(B.diagnostics().applications, 2);  // the fused call counts as an application
  }
}

// "auto" above the stresslet FMM's crossover but below kDirectSetUpCrossoverFactor times it (level
// 5, tolerance 1e-3: sqrt(30 720 × 10 242) = 17 740 against 9 300): the FMM back end, whose set-up
// pass sums directly and whose applications set the FMM up on first use. Against the forced direct
// operator on the same surface, then again after the surface moves (the FMM must follow it).
TEST(DoubleLayerSpheroid, DirectSetUpPassWithFmmApplicationsMatchesTheDirectOperator) {
  const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 5);
  Points x = spheroid_nodes(m);
  const Points u = field_without_symmetry(x);
  DoubleLayerOptions opt;
  opt.tolerance = 1e-3;
  // Every set-up computes D̃[1] in full: the moved surface is a uniform stretch, which the sampled
  // reuse (DoubleLayerIdentityReuse tests) may carry to within the tolerance, not to round-off.
  opt.reuse_identity_term = false;
  DoubleLayer A(m.triangles, m.num_nodes(), opt);
  opt.backend = BackendRequest::Direct;
  DoubleLayer D(m.triangles, m.num_nodes(), opt);
  ASSERT_EQ(A.backend(), FarFieldBackend::Fmm) << A.diagnostics().backend_reason;
  EXPECT_NE(A.diagnostics().backend_reason.find("set-up pass"), std::string::npos) << A.diagnostics().backend_reason;
  for (int move = 0; move < 2; ++move) {
    if (move == 1) x.col(0) *= 1.1;  // a new surface
    Points Au, Au2, Du;
    A.set_surface(x, &u, &Au);
    A.apply(u, Au2);
    D.set_surface(x);
    D.apply(u, Du);
    const double scale = Du.cwiseAbs().maxCoeff();
    // The set-up pass and its first application: the direct pairs in another grouping, round-off
    // only (~1e-15 relative; 1e-12 as in SetUpWithItsFirstApplicationEqualsSetUpThenApply).
    EXPECT_LT((Au - Du).cwiseAbs().maxCoeff(), 1e-12 * scale) << "surface " << move;
    // An FMM application at 0.25 × 1e-3: relative L2 error within that; 1e-3 leaves the 4× margin
    // of the tolerance. An FMM still set up on the first surface would sum the wrong geometry.
    EXPECT_LT((Au2 - Du).norm(), 1e-3 * Du.norm()) << "surface " << move;
  }
}

// An inexact application (allowed_error ≥ 1e-3: an inexact Krylov step of the viscosity-ratio
// solve) against the exact one at the levels where the direct far field is chosen, for a smooth
// field and a random one (a Krylov vector need not be smooth). Single-precision pairs where the
// build has AVX-512; the operator is the same otherwise.
TEST(DoubleLayerSpheroid, InexactApplicationsStayWellWithinTheAllowedError) {
  for (int level : {3, 4}) {
    const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, level);
    const Points x = spheroid_nodes(m), u = field_without_symmetry(x);
    const Points rough = Points::Random(m.num_nodes(), 3);
    DoubleLayerOptions opt;
    opt.backend = BackendRequest::Direct;
    opt.tolerance = 1e-6;
    DoubleLayer D(m.triangles, m.num_nodes(), opt);
    D.set_surface(x);
    for (const Points* v : {static_cast<const Points*>(&u), &rough}) {
      Points exact, inexact, just_below;
      D.apply(*v, exact);
      const double committed = D.apply(*v, inexact, 1e-3);
      D.apply(*v, just_below, 0.99e-3);
      // Single-precision pairs err by ~1e-7 of the image (the closest far-field pairs, ~h/2 apart,
      // lose ~6e-8/(h/2)): 2e-6 of it bounds them with room, and the bound the application reports
      // to GMRES (1e-6 of the density) must hold too.
      EXPECT_LT((inexact - exact).norm(), 2e-6 * exact.norm()) << "level " << level;
      if (fmm::kMixedPrecisionDirectSum) {
        EXPECT_GT((inexact - exact).norm(), 0.0);  // it did take the other path
        EXPECT_LT((inexact - exact).norm(), committed * v->norm()) << "level " << level;
        EXPECT_EQ((just_below - exact).norm(), 0.0);  // below the threshold: pairs in double
      }
    }
    EXPECT_EQ(D.diagnostics().inexact_applications, fmm::kMixedPrecisionDirectSum ? 2 : 0);
  }
}

// With the FMM back end an inexact step (allowed_error ≥ 1e-4) takes FMMs of lower orders: their
// images must stay within the allowance, and they must really be lower orders.
TEST(DoubleLayerSpheroid, InexactFmmApplicationsStayWithinTheAllowedError) {
  const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 4);
  const Points x = spheroid_nodes(m), u = field_without_symmetry(x);
  const Points rough = Points::Random(m.num_nodes(), 3);
  DoubleLayerOptions opt;
  opt.backend = BackendRequest::Fmm;
  opt.tolerance = 1e-6;
  DoubleLayer D(m.triangles, m.num_nodes(), opt);
  ASSERT_GT(D.diagnostics().inexact_fmm_order, 0);
  D.set_surface(x);
  for (const Points* v : {static_cast<const Points*>(&u), &rough}) {
    Points exact, inexact;
    D.apply(*v, exact);
    D.apply(*v, inexact, 1e-4);
    // The allowance is 1e-4 relative; the lower-order FMM asks for 2.5e-5 in relative L2 (4×
    // margin). The near field and the identity term are exact in both, so the far field's error
    // relative to the whole image can only be smaller.
    EXPECT_LT((inexact - exact).norm(), 1e-4 * exact.norm());
    EXPECT_GT((inexact - exact).norm(), 0.0);  // the other FMM did run
  }
  EXPECT_EQ(D.diagnostics().inexact_applications, 2);
  // Looser allowances take lower orders still (the GMRES steps near convergence): each within a
  // quarter of its allowance relative to the density in L2 (double_layer_fmm_tolerance's promise,
  // the solve's contract), each order below the next stricter one's, each taken only from its
  // allowance on.
  const auto tiers = D.diagnostics().inexact_fmm_uses;
  ASSERT_EQ(tiers.size(), 4u);  // p = 4, 5, 6, 7 below the exact p = 9 (kDoubleLayerOrders)
  for (size_t k = 0; k + 1 < tiers.size(); ++k) {
    EXPECT_GT(tiers[k].allowed_error, tiers[k + 1].allowed_error);
    EXPECT_LT(tiers[k].order, tiers[k + 1].order);
  }
  EXPECT_LT(tiers.back().order, D.fmm_order());
  for (const auto& t : tiers)
    for (const Points* v : {static_cast<const Points*>(&u), &rough}) {
      Points exact, inexact, just_below;
      D.apply(*v, exact);
      const double committed = D.apply(*v, inexact, t.allowed_error);
      D.apply(*v, just_below, 0.99 * t.allowed_error);  // the next stricter tier, or the exact order
      // The bound it reports (GMRES adds it up) is the quarter of the allowance the order was chosen for.
      EXPECT_DOUBLE_EQ(committed, 0.25 * t.allowed_error) << "order " << t.order;
      // Measured at 81 920 elements (random density, the worst): 7.8e-4, 4.0e-4, 2.7e-5 and 1.4e-6
      // at p = 4, 5, 6, 7 relative to ‖v‖, against bounds of 2.5e-3, 1.25e-3, 2.5e-4 and 2.5e-5.
      EXPECT_LT((inexact - exact).norm(), committed * v->norm()) << "order " << t.order;
      EXPECT_GT((inexact - just_below).norm(), 0.0) << "order " << t.order;  // a different FMM ran
    }
  const auto used = D.diagnostics().inexact_fmm_uses;
  // Per tier two densities at its allowance, two just below the next looser tier's, and the
  // strictest the two of the first part.
  for (size_t k = 0; k < used.size(); ++k)
    EXPECT_EQ(used[k].applications, (k == 0 ? 2 : 4) + (k + 1 == used.size() ? 2 : 0)) << "order " << used[k].order;
}
