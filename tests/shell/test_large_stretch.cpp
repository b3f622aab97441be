// The membrane response of the discrete wall at large stretch, against closed forms
// derived here from the strain energies (not from the law code):
//  1. tension-stretch curves of a flat P1 patch (arbitrary 3-D orientation, triangles not aligned
//     with the stretch) in uniaxial and equibiaxial tension, NH and Skalak, stretches up to 3;
//  2. the inflated sphere: pressure-radius law p(lambda) = 2 T(lambda) / (lambda a), up to 3;
//  3. a sphere stretched non-uniformly into a prolate spheroid (hoop stretch alpha, meridional
//     stretch from alpha at the poles to beta at the equator): the exact load follows from the
//     axisymmetric membrane equilibrium; the discrete load (consistent and lumped mass) is compared
//     in weak form and pointwise.
// Closed forms (Barthes-Biesel, Diaz & Dhenin 2002, J. Fluid Mech. 460, re-derived):
//   W_NH = (Gs/2)(I1 - 1 + 1/(I2 + 1)),  W_SK = (Gs/4)(I1^2 + 2 I1 - 2 I2 + C I2^2),
//   I1 = l1^2 + l2^2 - 2, I2 = l1^2 l2^2 - 1. Cauchy tension T1 = (1/l2) dW/dl1 (force per deformed
//   length); equibiaxial T = (1/(2 l)) dW/dl; uniaxial: dW/dl2 = 0 fixes l2.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

#include "capsflow/shell/load_recovery.hpp"
#include "capsflow/shell/topology.hpp"
#include "capsflow/shell/wall.hpp"
#include "support/test_meshes.hpp"

using namespace capsflow::shell;
using namespace capsflow::shell::testing;

namespace {

// Closed-form principal Cauchy tension along l1 (the law code is not used).
double T_nh(double Gs, double l1, double l2) {
  const double J = l1 * l2;
  return Gs / J * (l1 * l1 - 1.0 / (J * J));
}
double T_sk(double Gs, double C, double l1, double l2) {
  return Gs * l1 / l2 * (l1 * l1 - 1.0 + C * l2 * l2 * (l1 * l1 * l2 * l2 - 1.0));
}
// Uniaxial tension (T2 = 0): NH l2 = l1^(-1/2); SK l2^2 = (1 + C l1^2)/(1 + C l1^4).
double l2_uniaxial_nh(double l1) { return 1.0 / std::sqrt(l1); }
double l2_uniaxial_sk(double C, double l1) { return std::sqrt((1 + C * l1 * l1) / (1 + C * std::pow(l1, 4))); }

Eigen::Matrix3d rotation(double a, double b, double c) {
  return (Eigen::AngleAxisd(a, Vec3::UnitZ()) * Eigen::AngleAxisd(b, Vec3::UnitY()) *
          Eigen::AngleAxisd(c, Vec3::UnitX()))
      .toRotationMatrix();
}

}  // namespace

TEST(LargeStretch, FlatPatchFollowsUniaxialAndEquibiaxialClosedForms) {
  // A 2 x 1 patch, 12 x 7 cells, criss-cross pattern (triangles in two orientations, none aligned
  // with the principal axes of the triangles' own edges), deformed homogeneously by
  // x = Q diag(l1, l2, 1) X with a generic rotation Q into 3-D. A homogeneous deformation is
  // represented exactly by P1, so: interior nodal forces vanish and the edge resultants equal the
  // Cauchy tension times the deformed edge length, to round-off.
  const Mesh m = plate(2.0, 1.0, 12, 7, 1);
  const Eigen::Matrix3d Q = rotation(0.7, -0.4, 1.1);
  const double Gs = 1.7;
  struct Case {
    const char* law;
    double C;
  };
  for (const Case& c : {Case{"nh", 0.0}, Case{"skalak", 1.0}, Case{"skalak", 10.0}}) {
    const MembraneLaw law = make_law(c.law, Gs, 0.5, c.C);
    const bool nh = std::string(c.law) == "nh";
    MembraneWall wall(m.X, m.T, law);
    for (double l1 : {1.1, 1.5, 2.0, 2.5, 3.0})
      for (int mode = 0; mode < 2; ++mode) {  // 0 uniaxial, 1 equibiaxial
        const double l2 = mode == 1 ? l1 : (nh ? l2_uniaxial_nh(l1) : l2_uniaxial_sk(c.C, l1));
        const double T1 = nh ? T_nh(Gs, l1, l2) : T_sk(Gs, c.C, l1, l2);
        const double T2 = nh ? T_nh(Gs, l2, l1) : T_sk(Gs, c.C, l2, l1);
        if (mode == 0) {
          EXPECT_NEAR(T2, 0.0, 1e-12 * T1) << "closed-form uniaxial state";  // algebra check
        }
        Points x(m.X.rows(), 3);
        for (Eigen::Index i = 0; i < x.rows(); ++i)
          x.row(i) = (Q * Vec3(l1 * m.X(i, 0), l2 * m.X(i, 1), m.X(i, 2))).transpose();
        Points R;
        wall.forces(x, R);
        const Vec3 e1 = Q.col(0), e2 = Q.col(1);
        double right = 0, top = 0, interior = 0;
        for (Eigen::Index i = 0; i < x.rows(); ++i) {
          const bool on_right = std::abs(m.X(i, 0) - 2.0) < 1e-12, on_top = std::abs(m.X(i, 1) - 1.0) < 1e-12;
          const bool on_edge = on_right || on_top || m.X(i, 0) < 1e-12 || m.X(i, 1) < 1e-12;
          if (on_right) right += Vec3(R.row(i)).dot(e1);
          if (on_top) top += Vec3(R.row(i)).dot(e2);
          if (!on_edge) interior = std::max(interior, R.row(i).norm());
        }
        const double scale = std::abs(T1) * l2;  // nodal force scale (tension x length)
        // Round-off only (sums of O(1) terms): 1e-11 relative.
        EXPECT_NEAR(right, T1 * l2 * 1.0, 1e-11 * scale) << c.law << " C=" << c.C << " l1=" << l1 << " mode " << mode;
        EXPECT_NEAR(top, T2 * l1 * 2.0, 1e-11 * scale) << c.law << " C=" << c.C << " l1=" << l1 << " mode " << mode;
        EXPECT_LT(interior, 1e-11 * scale) << c.law << " l1=" << l1 << " mode " << mode;
      }
  }
}

TEST(LargeStretch, InflatedSpherePressureRadiusLaw) {
  // x = lambda X on the level-4 icosphere (unit sphere, a = 1). The pressure that holds the
  // inflated membrane is p = 2 T(lambda)/lambda (Laplace), T the equibiaxial tension:
  //   NH: T = Gs (1 - lambda^-6) (maximum pressure at lambda = 7^(1/6) = 1.383);
  //   SK: T = Gs [lambda^2 - 1 + C lambda^2 (lambda^4 - 1)].
  // Discrete pressure: the virtual work of R along the radial scaling, sum_i R_i.X_i, divided by
  // dV_h/dlambda = 3 lambda^2 V_h(1). O(h^2) from the facet geometry (A_h/V_h vs 3/a).
  // The pointwise load at nodes >= 3 rings from the valence-5 vertices is compared with p n too.
  // (For a uniform stretch the discrete load is T(lambda) times a lambda-independent field, so the
  // relative errors here cannot grow with lambda; the non-uniform case is the next test.)
  const Mesh m = icosphere(4);
  const Topology topo(m.T, m.X.rows());
  std::vector<int> ring(m.X.rows(), 99);
  for (int i = 0; i < topo.n_nodes; ++i)
    if (topo.inc_ptr[i + 1] - topo.inc_ptr[i] == 5) ring[i] = 0;
  for (int r = 0; r < 3; ++r)
    for (int i = 0; i < topo.n_nodes; ++i)
      if (ring[i] == r)
        for (int p = topo.adj_ptr[i]; p < topo.adj_ptr[i + 1]; ++p) ring[topo.adj[p]] = std::min(ring[topo.adj[p]], r + 1);
  double V1 = 0;
  for (Eigen::Index e = 0; e < m.T.rows(); ++e)
    V1 += Vec3(m.X.row(m.T(e, 0))).dot(Vec3(m.X.row(m.T(e, 1))).cross(Vec3(m.X.row(m.T(e, 2))))) / 6.0;
  LoadRecovery lr(m.T, m.X.rows());
  for (const char* name : {"nh", "skalak"}) {
    const double Gs = 1.0, C = 1.0;
    MembraneWall wall(m.X, m.T, make_law(name, Gs, 0.5, C));
    for (double lam : {1.2, 1.383, 1.5, 2.0, 3.0}) {
      const double T = std::string(name) == "nh" ? Gs * (1 - std::pow(lam, -6))
                                                 : Gs * (lam * lam - 1 + C * lam * lam * (std::pow(lam, 4) - 1));
      const double p = 2 * T / lam;
      const Points x = lam * m.X;
      Points R, q;
      wall.forces(x, R);
      lr.solve(x, R, q);
      double work = 0, err_far = 0;
      for (Eigen::Index i = 0; i < x.rows(); ++i) {
        work += Vec3(R.row(i)).dot(Vec3(m.X.row(i)));
        if (ring[i] >= 3) err_far = std::max(err_far, (Vec3(q.row(i)) - p * Vec3(m.X.row(i))).norm() / p);
      }
      const double p_h = work / (3 * lam * lam * V1);
      std::printf("%s lambda %.3f: p_h/p - 1 = %.2e, pointwise far %.2e\n", name, lam, p_h / p - 1, err_far);
      // measured 9.68e-4 at level 4 for every lambda and law (the facet geometry: A_h a / (3 V_h) - 1);
      // bound 1.25x measured
      EXPECT_NEAR(p_h / p, 1.0, 1.2e-3) << name << " lambda " << lam;
      EXPECT_LT(err_far, 1e-2) << name << " lambda " << lam;  // measured 6.4e-3 for every lambda and law
    }
  }
}

namespace {

// The exact load on the affine image x = (alpha X1, alpha X2, beta X3) of the unit sphere.
// With X = (sin t cos f, sin t sin f, cos t): r = alpha sin t, z = beta cos t, hoop stretch
// l_f = alpha, meridional stretch l_s = sqrt(alpha^2 cos^2 t + beta^2 sin^2 t). Axisymmetric
// membrane equilibrium, q = -div_s(T) = (k_s T_s + k_f T_f) n - (1/r)[d(r T_s)/ds - T_f dr/ds] t,
// t the unit meridional tangent (increasing t), n outward, ds = l_s dt,
// k_s = alpha beta / l_s^3, k_f = beta / (alpha l_s).
struct SpheroidLoad {
  double alpha, beta;
  std::function<double(double, double)> T;  // T(l1, l2): Cauchy tension along l1
  double ls(double t) const { return std::sqrt(alpha * alpha * std::cos(t) * std::cos(t) + beta * beta * std::sin(t) * std::sin(t)); }
  double rTs(double t) const { return alpha * std::sin(t) * T(ls(t), alpha); }
  // load in cylindrical components (q_r, q_z) at polar angle t (0 < t < pi)
  void q(double t, double& qr, double& qz) const {
    const double l = ls(t), r = alpha * std::sin(t);
    const double Ts = T(l, alpha), Tf = T(alpha, l);
    const double ks = alpha * beta / (l * l * l), kf = beta / (alpha * l);
    const double h = 1e-3;  // 4th-order central difference: error ~ h^4 = 1e-12
    const double drTs = (-rTs(t + 2 * h) + 8 * rTs(t + h) - 8 * rTs(t - h) + rTs(t - 2 * h)) / (12 * h) / l;
    const double drds = alpha * std::cos(t) / l;
    const double qn = ks * Ts + kf * Tf, qt = -(drTs - Tf * drds) / r;
    const double tr = alpha * std::cos(t) / l, tz = -beta * std::sin(t) / l;  // unit tangent
    const double nr = beta * std::sin(t) / l, nz = alpha * std::cos(t) / l;   // unit outward normal
    qr = qn * nr + qt * tr;
    qz = qn * nz + qt * tz;
  }
  Vec3 q_at(const Vec3& X) const {  // X on the unit sphere
    const double t = std::acos(std::clamp(X[2], -1.0, 1.0));
    const double rho = std::hypot(X[0], X[1]);
    if (rho < 1e-12) {  // pole: isotropic tension alpha, alpha; q = 2 k T n with k = beta / alpha^2
      const double T0 = T(alpha, alpha);
      return Vec3(0, 0, (X[2] > 0 ? 1 : -1) * 2 * beta / (alpha * alpha) * T0);
    }
    double qr, qz;
    q(t, qr, qz);
    return Vec3(qr * X[0] / rho, qr * X[1] / rho, qz);
  }
};

// The 12 valence-5 vertices of an icosphere.
std::vector<int> valence5(const Topology& topo) {
  std::vector<int> out;
  for (int i = 0; i < topo.n_nodes; ++i)
    if (topo.inc_ptr[i + 1] - topo.inc_ptr[i] == 5) out.push_back(i);
  return out;
}
// Nodes on the 30 "seams" of an icosphere: the great-circle arcs between neighbouring valence-5
// vertices (the edges of the original icosahedron), where the subdivided-and-projected mesh
// changes its local pattern.
std::vector<int> seam_nodes(const Points& X, const Topology& topo) {
  const std::vector<int> v5 = valence5(topo);
  std::vector<int> out;
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const Vec3 p = X.row(i);
    bool on = false;
    for (size_t a = 0; a < v5.size() && !on; ++a)
      for (size_t b = a + 1; b < v5.size() && !on; ++b) {
        const Vec3 A = X.row(v5[a]), B = X.row(v5[b]);
        const double c = A.dot(B);
        if (c < 0.4) continue;  // neighbours: cos(63.43 deg) = 0.447
        on = std::abs(A.cross(B).normalized().dot(p)) < 1e-9 && p.dot(A) > c - 1e-9 && p.dot(B) > c - 1e-9;
      }
    if (on) out.push_back(static_cast<int>(i));
  }
  return out;
}
// Ring distance (edge hops, capped at `depth`) from a set of nodes.
std::vector<int> rings_from(const Topology& topo, const std::vector<int>& seeds, int depth) {
  std::vector<int> ring(topo.n_nodes, depth);
  for (int i : seeds) ring[i] = 0;
  for (int r = 0; r < depth; ++r)
    for (int i = 0; i < topo.n_nodes; ++i)
      if (ring[i] == r)
        for (int p = topo.adj_ptr[i]; p < topo.adj_ptr[i + 1]; ++p) ring[topo.adj[p]] = std::min(ring[topo.adj[p]], r + 1);
  return ring;
}

}  // namespace

TEST(LargeStretch, StretchedSpheroidLoadMatchesAxisymmetricEquilibrium) {
  // Non-uniform, non-equibiaxial large stretch of the reference sphere: the loaded membrane in the
  // capsule at Ca_s = 0.6 has meridional stretches ~1.8 and hoop compression ~0.8. Measures
  // (a) the weak form sum_i R_i . psi(X_i) against int q . psi dS on the exact spheroid, psi
  //     smooth (O(h^2) expected: the discrete virtual work of a smooth field);
  // (b) the pointwise load q_h = M^-1 R (consistent) and R / lumped mass: inside the faces of the
  //     original icosahedron, on its 30 seams, and at its 12 valence-5 vertices.
  struct Case {
    const char* name;
    double alpha, beta;
  };
  const double Gs = 1.0, C = 1.0;
  const std::function<double(double, double)> nh = [&](double a, double b) { return T_nh(Gs, a, b); };
  const std::function<double(double, double)> sk = [&](double a, double b) { return T_sk(Gs, C, a, b); };
  for (const Case& c : {Case{"nh", 0.8, 1.8}, Case{"nh", 1.2, 2.5}, Case{"skalak", 0.8, 1.8}}) {
    const SpheroidLoad ex{c.alpha, c.beta, std::string(c.name) == "nh" ? nh : sk};
    const MembraneLaw law = make_law(c.name, Gs, 0.5, C);
    // int q . psi dS on the exact deformed surface, psi(X) = (X1 X3^2, X2, X3 + X1^2) (X on the
    // unit sphere; smooth, not axisymmetric). dS = l_s l_f sin t dt df; Gauss-Legendre in t (64),
    // trapezoid in f (128, exact for the trigonometric integrand).
    auto psi = [](const Vec3& X) { return Vec3(X[0] * X[2] * X[2], X[1], X[2] + X[0] * X[0]); };
    double weak_exact = 0;
    {
      const int nt = 64, nf = 128;
      Eigen::VectorXd gx(nt), gw(nt);
      // Gauss-Legendre nodes by Newton on P_n
      for (int i = 0; i < nt; ++i) {
        double z = std::cos(M_PI * (i + 0.75) / (nt + 0.5)), pp = 0;
        for (int it = 0; it < 100; ++it) {
          double p0 = 1, p1 = z;
          for (int k = 2; k <= nt; ++k) {
            const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
            p0 = p1;
            p1 = p2;
          }
          pp = nt * (z * p1 - p0) / (z * z - 1);
          const double dz = p1 / pp;
          z -= dz;
          if (std::abs(dz) < 1e-15) break;
        }
        gx[i] = z;
        gw[i] = 2 / ((1 - z * z) * pp * pp);
      }
      for (int i = 0; i < nt; ++i) {
        const double t = 0.5 * M_PI * (gx[i] + 1), wt = 0.5 * M_PI * gw[i];
        for (int j = 0; j < nf; ++j) {
          const double f = 2 * M_PI * j / nf;
          const Vec3 X(std::sin(t) * std::cos(f), std::sin(t) * std::sin(f), std::cos(t));
          weak_exact += wt * (2 * M_PI / nf) * ex.ls(t) * c.alpha * std::sin(t) * ex.q_at(X).dot(psi(X));
        }
      }
    }
    double prev_weak = 1e9;
    for (int level : {2, 3, 4, 5}) {
      const Mesh m = icosphere(level);
      Points x(m.X.rows(), 3);
      for (Eigen::Index i = 0; i < x.rows(); ++i) x.row(i) << c.alpha * m.X(i, 0), c.alpha * m.X(i, 1), c.beta * m.X(i, 2);
      MembraneWall wall(m.X, m.T, law);
      Points R, q, ql;
      wall.forces(x, R);
      LoadRecovery lr(m.T, m.X.rows());
      lr.solve(x, R, q);
      lr.solve_lumped(x, R, ql);
      const Topology topo(m.T, m.X.rows());
      const std::vector<int> v5ring = rings_from(topo, valence5(topo), 3);
      const std::vector<int> seam = rings_from(topo, seam_nodes(m.X, topo), 2);
      double weak = 0, qmax = 0, far = 0, far_l = 0, v5 = 0, v5_l = 0, seam_e = 0, seam_l = 0;
      for (Eigen::Index i = 0; i < x.rows(); ++i) qmax = std::max(qmax, ex.q_at(m.X.row(i)).norm());
      for (Eigen::Index i = 0; i < x.rows(); ++i) {
        const Vec3 X = m.X.row(i), qe = ex.q_at(X);
        weak += Vec3(R.row(i)).dot(psi(X));
        const double e = (Vec3(q.row(i)) - qe).norm() / qmax, el = (Vec3(ql.row(i)) - qe).norm() / qmax;
        if (seam[i] >= 2) far = std::max(far, e), far_l = std::max(far_l, el);
        if (seam[i] == 0 && v5ring[i] >= 3) seam_e = std::max(seam_e, e), seam_l = std::max(seam_l, el);
        if (v5ring[i] == 0) v5 = std::max(v5, e), v5_l = std::max(v5_l, el);
      }
      const double werr = std::abs(weak - weak_exact) / std::abs(weak_exact);
      std::printf("%s alpha %.2f beta %.2f level %d: weak %.2e | pointwise/max|q| consistent (lumped): inside faces"
                  " %.2e (%.2e), on seams %.2e (%.2e), valence-5 %.2e (%.2e)\n",
                  c.name, c.alpha, c.beta, level, werr, far, far_l, seam_e, seam_l, v5, v5_l);
      if (level >= 3) {
        EXPECT_GT(prev_weak / werr, 3.5) << c.name << level;  // O(h^2): measured ratios 3.86-4.00
      }
      prev_weak = werr;
      if (level == 5) {
        // Weak form: measured 1.44e-4 (NH 0.8/1.8), 2.94e-4 (NH 1.2/2.5), 2.49e-4 (SK): bound 4e-4.
        EXPECT_LT(werr, 4e-4) << c.name;
        // Pointwise: the Galerkin load q_h = M^-1 R converges only in weak form. Its nodal values
        // keep an O(1) (mesh-independent) error where the icosphere's local pattern is not
        // symmetric: at the 12 valence-5 vertices (measured 0.105 / 0.278 / 0.327 of max|q|,
        // lumped 0.045 / 0.119 / 0.140) and along the 30 seams of the original icosahedron
        // (0.025 / 0.010 / 0.074, lumped 0.011 / 0.006 / 0.033); inside the faces (>= 2 rings from
        // a seam) 0.013 / 0.008 / 0.027. These bounds (1.1-1.4x measured) pin the defect's size.
        EXPECT_LT(v5, 0.36) << c.name;
        EXPECT_LT(v5_l, 0.16) << c.name;
        EXPECT_LT(seam_e, 0.09) << c.name;
        EXPECT_LT(far, 0.035) << c.name;
        EXPECT_LT(v5_l, v5) << c.name;  // lumped mass: smaller nodal defect (not more accurate in weak form)
      }
    }
  }
}
