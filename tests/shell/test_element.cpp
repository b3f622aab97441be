// MITC3 GSMB element: derivatives against finite differences and automatic differentiation,
// objectivity, MITC3 shear-field invariants, rigid-body modes, and the pinned energy factors.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "capsflow/shell/hyperdual.hpp"
#include "support/wall_fixtures.hpp"

using namespace capsflow::shell;
using namespace capsflow::shell::testing;

namespace {

struct Fixture {
  Mesh m = icosphere(1);
  GsmbOptions opt;
  std::unique_ptr<GsmbWall> wall;
  Points x;
  explicit Fixture(const char* law = "nh", double h = 0.1) {
    opt.thickness = h;
    opt.poisson = 0.4;
    wall = std::make_unique<GsmbWall>(m.X, m.T, make_law(law, 1.0, 0.4, 1.5), opt);
    x = deform(m.X, 1.0, 3);
    wall->rotate(random_w(m.X.rows(), 0.3, 5));
  }
  double E(const Points& y) const { return wall->energies(y).total(); }
};

double maxabs(const Points& p) { return p.cwiseAbs().maxCoeff(); }

}  // namespace

TEST(Element, NodalForcesMatchFiniteDifferencesOfEnergy) {
  for (const char* law : {"nh", "gh", "skalak"}) {
    Fixture f(law);
    Points fx;
    f.wall->evaluate(f.x, &fx, nullptr, false);
    const double scale = maxabs(fx);
    const double h = 1e-6;
    double worst = 0;
    for (Eigen::Index i = 0; i < f.x.rows(); i += 3)
      for (int c = 0; c < 3; ++c) {
        Points xp = f.x, xm = f.x;
        xp(i, c) += h;
        xm(i, c) -= h;
        const double fd = (f.E(xp) - f.E(xm)) / (2 * h);
        worst = std::max(worst, std::abs(fd - fx(i, c)));
      }
    // central differences with h = 1e-6: truncation ~h^2 E''' ~ 1e-12, round-off ~eps E/h ~ 1e-10
    EXPECT_LT(worst, 1e-6 * scale) << law;
  }
}

TEST(Element, RotationResidualMatchesFiniteDifferencesOfEnergy) {
  Fixture f;
  Eigen::VectorXd R;
  f.wall->evaluate(f.x, nullptr, &R, false);
  const Eigen::VectorXd s0 = f.wall->state();
  const double h = 1e-6;
  double worst = 0;
  const int n2 = static_cast<int>(R.size());
  for (int k = 0; k < n2; k += 5) {
    Eigen::VectorXd w = Eigen::VectorXd::Zero(n2);
    w[k] = h;
    f.wall->rotate(w);
    const double ep = f.E(f.x);
    f.wall->set_state(s0);
    w[k] = -h;
    f.wall->rotate(w);
    const double em = f.E(f.x);
    f.wall->set_state(s0);
    worst = std::max(worst, std::abs((ep - em) / (2 * h) - R[k]));
  }
  // same FD error budget as for the forces; relative to the largest moment
  EXPECT_LT(worst, 1e-6 * R.cwiseAbs().maxCoeff());
}

TEST(Element, TangentMatchesSecondDifferencesOfEnergy) {
  Fixture f;
  f.wall->options().geometric_tangent = false;  // material part only; geometric part added below
  Eigen::VectorXd R;
  f.wall->evaluate(f.x, nullptr, &R, true);
  SpMatR H = f.wall->tangent();
  const Points& g = f.wall->director_forces();
  const Points& d = f.wall->directors();
  for (Eigen::Index i = 0; i < d.rows(); ++i) {
    const double c = -g.row(i).dot(d.row(i));
    H.coeffRef(2 * i, 2 * i) += c;
    H.coeffRef(2 * i + 1, 2 * i + 1) += c;
  }
  const Eigen::VectorXd s0 = f.wall->state();
  const double E0 = f.E(f.x);
  const int n2 = static_cast<int>(R.size());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int trial = 0; trial < 8; ++trial) {
    Eigen::VectorXd v(n2);
    if (trial < 4) {  // single entries and pairs probe diagonal and off-diagonal blocks
      v.setZero();
      v[7 * trial] = 1;
      if (trial >= 2) v[7 * trial + 3] = 1;
    } else {
      for (int i = 0; i < n2; ++i) v[i] = U(rng);
    }
    const double eps = 1e-4;
    f.wall->rotate(eps * v);
    const double ep = f.E(f.x);
    f.wall->set_state(s0);
    f.wall->rotate(-eps * v);
    const double em = f.E(f.x);
    f.wall->set_state(s0);
    const double fd = (ep - 2 * E0 + em) / (eps * eps);
    const double vHv = v.dot(H * v);
    // truncation O(eps^2) ~ 1e-8 relative, round-off eps_mach E0/eps^2 ~ 1e-8 E0
    EXPECT_NEAR(vHv, fd, 1e-5 * std::abs(vHv) + 1e-7 * E0) << trial;
  }
}

TEST(Element, HandCodedDerivativesMatchAutomaticDifferentiation) {
  // One curved element with random directors; variables x (9) and rotation increments w (6).
  Fixture f;
  const ElementRef& R = f.wall->elements()[5];
  const auto& nd = R.m.n;
  const Points& d = f.wall->directors();
  const Points& t1 = f.wall->t1();
  const Points& t2 = f.wall->t2();
  using H = Hyper<15>;
  H xs[3][3], ds[3][3];
  for (int a = 0; a < 3; ++a) {
    for (int c = 0; c < 3; ++c) xs[a][c] = H::variable(f.x(nd[a], c), 3 * a + c);
    const H w1 = H::variable(0.0, 9 + 2 * a), w2 = H::variable(0.0, 10 + 2 * a);
    // d(w) = d + w x d + 1/2 w x (w x d), w = w1 t1 + w2 t2: exact to 2nd order at w = 0
    H w[3], dd[3];
    for (int c = 0; c < 3; ++c) { w[c] = w1 * t1(nd[a], c) + w2 * t2(nd[a], c); dd[c] = H(d(nd[a], c)); }
    auto cross = [](const H* p, const H* q, H* r) {
      r[0] = p[1] * q[2] - p[2] * q[1]; r[1] = p[2] * q[0] - p[0] * q[2]; r[2] = p[0] * q[1] - p[1] * q[0];
    };
    H wd[3], wwd[3];
    cross(w, dd, wd);
    cross(w, wd, wwd);
    for (int c = 0; c < 3; ++c) ds[a][c] = dd[c] + wd[c] + 0.5 * wwd[c];
  }
  H out[3];
  element_energy_t(R, f.wall->law(), xs, ds, out);
  const H E = out[0] + out[1] + out[2];
  // hand-coded
  Vec3 xe[3], de[3], T[3][2], fm[3];
  for (int a = 0; a < 3; ++a) {
    xe[a] = f.x.row(nd[a]);
    de[a] = d.row(nd[a]);
    T[a][0] = -t2.row(nd[a]).transpose();
    T[a][1] = t1.row(nd[a]).transpose();
  }
  BsOut o;
  const double wm = membrane_element(R.m, f.wall->law(), xe, fm);
  bs_element(R, xe, de, T, o, true);
  const double tol = 1e-11;  // same arithmetic in a different order: round-off only
  EXPECT_NEAR(E.v, wm + o.Eb + o.Es, tol * std::abs(E.v));
  double gs = 0, ks = 0;
  for (int i = 0; i < 15; ++i) gs = std::max(gs, std::abs(E.g[i]));
  for (int a = 0; a < 3; ++a)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(E.g[3 * a + c], fm[a][c] + o.fx[a][c], tol * gs);
  for (int a = 0; a < 3; ++a)
    for (int k = 0; k < 2; ++k) EXPECT_NEAR(E.g[9 + 2 * a + k], T[a][k].dot(o.g[a]), tol * gs);
  for (int i = 9; i < 15; ++i)
    for (int j = 9; j < 15; ++j) ks = std::max(ks, std::abs(E.hess(i, j)));
  for (int a = 0; a < 6; ++a)
    for (int b = 0; b < 6; ++b) {
      const double geo = (a == b) ? -o.g[a / 2].dot(de[a / 2]) : 0.0;
      EXPECT_NEAR(E.hess(9 + a, 9 + b), o.K[a][b] + geo, 1e-10 * ks) << a << "," << b;
    }
}

TEST(Element, RigidMotionInvariance) {
  Fixture f("skalak");
  Points fx0;
  f.wall->evaluate(f.x, &fx0, nullptr, false);
  const Points g0 = f.wall->director_forces();
  const double E0 = f.E(f.x);
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(2.7, Vec3(0.3, -0.8, 0.5).normalized()).toRotationMatrix();
  const Vec3 c(3.0, -1.0, 2.0);
  Points y = f.x;
  for (Eigen::Index i = 0; i < y.rows(); ++i) y.row(i) = (Q * Vec3(f.x.row(i)) + c).transpose();
  Points dq = f.wall->directors();
  for (Eigen::Index i = 0; i < dq.rows(); ++i) dq.row(i) = (Q * Vec3(dq.row(i))).transpose();
  f.wall->set_directors(dq);
  Points fx1;
  f.wall->evaluate(y, &fx1, nullptr, false);
  const Points g1 = f.wall->director_forces();
  // objectivity holds exactly in exact arithmetic: only round-off (coordinates ~3) remains
  EXPECT_NEAR(f.E(y), E0, 1e-12 * std::abs(E0) * 100);
  double err = 0, errg = 0;
  for (Eigen::Index i = 0; i < y.rows(); ++i) {
    err = std::max(err, (Vec3(fx1.row(i)) - Q * Vec3(fx0.row(i))).norm());
    errg = std::max(errg, (Vec3(g1.row(i)) - Q * Vec3(g0.row(i))).norm());
  }
  EXPECT_LT(err, 1e-12 * maxabs(fx0) * 100);  // 1e-10 relative: round-off of O(10)-term sums with |x|~3
  EXPECT_LT(errg, 1e-12 * maxabs(g0) * 100);
  // rigid motion of the reference state: zero energy and zero forces
  Fixture r("gh");
  Points yr = r.m.X, dr = r.wall->reference_directors();
  for (Eigen::Index i = 0; i < yr.rows(); ++i) {
    yr.row(i) = (Q * Vec3(r.m.X.row(i)) + c).transpose();
    dr.row(i) = (Q * Vec3(dr.row(i))).transpose();
  }
  r.wall->set_directors(dr);
  Points fr;
  Eigen::VectorXd Rr;
  r.wall->evaluate(yr, &fr, &Rr, false);
  EXPECT_LT(r.E(yr), 1e-12 * E0);
  EXPECT_LT(maxabs(fr), 1e-12 * maxabs(fx0) * 100);
  EXPECT_LT(Rr.cwiseAbs().maxCoeff(), 1e-12 * maxabs(g0) * 100);
}

TEST(Element, Mitc3ShearFieldInvariants) {
  double M[2][4];
  // a constant covariant field (zr, zs) has tying values (zr, zs, zr, zs) and is reproduced
  const double zr = 0.37, zs = -1.2, tc[4] = {zr, zs, zr, zs};
  for (double r : {0.0, 0.2, 0.5, 1.0})
    for (double s : {0.0, 0.3, 1.0 - r}) {
      mitc3_shear_map(r, s, M);
      EXPECT_NEAR(M[0][0] * tc[0] + M[0][1] * tc[1] + M[0][2] * tc[2] + M[0][3] * tc[3], zr, 1e-15);
      EXPECT_NEAR(M[1][0] * tc[0] + M[1][1] * tc[1] + M[1][2] * tc[2] + M[1][3] * tc[3], zs, 1e-15);
    }
  // arbitrary tying values: tangential components constant along each edge and equal to the tying value
  const double t[4] = {0.3, -0.7, 1.1, 0.45};
  auto field = [&](double r, double s, double z[2]) {
    mitc3_shear_map(r, s, M);
    for (int a = 0; a < 2; ++a) z[a] = M[a][0] * t[0] + M[a][1] * t[1] + M[a][2] * t[2] + M[a][3] * t[3];
  };
  for (double u : {0.0, 0.25, 0.5, 0.9, 1.0}) {
    double z[2];
    field(u, 0.0, z);  // edge 1-2 (s = 0), tangent (1, 0)
    EXPECT_NEAR(z[0], t[0], 1e-15);
    field(0.0, u, z);  // edge 1-3 (r = 0), tangent (0, 1)
    EXPECT_NEAR(z[1], t[1], 1e-15);
    field(1.0 - u, u, z);  // edge 2-3, tangent (-1, 1)
    EXPECT_NEAR(z[1] - z[0], t[3] - t[2], 1e-15);
  }
}

TEST(Element, FlatElementHasExactlySixRigidBodyModes) {
  const Vec3 X[3] = {Vec3(0.1, 0.0, 0.0), Vec3(1.0, 0.2, 0.0), Vec3(0.3, 0.9, 0.0)};
  const Vec3 D[3] = {Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, 1)};
  const ElementRef R = make_element_ref(X, D, {0, 1, 2}, 0.05, 1.0, 0.3);
  const MembraneLaw law = make_law("gh", 0.05, 0.3);
  Vec3 t1, t2;
  tangent_basis(D[0], t1, t2);
  using H = Hyper<15>;
  H xs[3][3], ds[3][3];
  for (int a = 0; a < 3; ++a) {
    for (int c = 0; c < 3; ++c) xs[a][c] = H::variable(X[a][c], 3 * a + c);
    const H w1 = H::variable(0.0, 9 + 2 * a), w2 = H::variable(0.0, 10 + 2 * a);
    // d(w) to 2nd order; with d = e_z: w x d and w x (w x d) written out
    H w[3];
    for (int c = 0; c < 3; ++c) w[c] = w1 * t1[c] + w2 * t2[c];
    const H wd[3] = {w[1], -w[0], H(0.0)};             // w x e_z
    const H wwd[3] = {-w[2] * w[0], -w[2] * w[1], w[0] * w[0] + w[1] * w[1]};  // w x (w x e_z) = w w_z - e_z |w|^2
    for (int c = 0; c < 3; ++c) ds[a][c] = H(D[a][c]) + wd[c] + 0.5 * (c == 2 ? -1.0 * wwd[2] : wwd[c]);
  }
  H out[3];
  element_energy_t(R, law, xs, ds, out);
  const H E = out[0] + out[1] + out[2];
  Eigen::Matrix<double, 15, 15> K;
  for (int i = 0; i < 15; ++i)
    for (int j = 0; j < 15; ++j) K(i, j) = E.hess(i, j);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 15, 15>> es(K);
  const auto ev = es.eigenvalues();
  const double lmax = ev.cwiseAbs().maxCoeff();
  int zeros = 0;
  for (int i = 0; i < 15; ++i) zeros += std::abs(ev[i]) < 1e-12 * lmax;  // round-off of a 15x15 eig
  EXPECT_EQ(zeros, 6);
  EXPECT_GT(ev[6], 1e-8 * lmax);  // smallest deformation mode (bending ~ h^2 x membrane) clearly positive
  EXPECT_GT(ev.minCoeff(), -1e-12 * lmax);
}

TEST(Element, UniformTransverseShearPinsTheShearFactor) {
  // flat plate, x = X, all directors tilted by phi about y: zeta_x = sin(phi)/2 (tensor shear),
  // engineering shear sin(phi), energy = (G h / 2) sin^2(phi) * Area (no correction factor).
  Mesh p = plate(2.0, 1.0, 6, 3, 1);
  GsmbOptions o;
  o.thickness = 0.1;
  o.poisson = 0.3;
  const double Gs = 0.7, G = Gs / o.thickness, phi = 0.2;
  GsmbWall w(p.X, p.T, make_law("gh", Gs, 0.3), o);
  Points d(p.X.rows(), 3);
  for (Eigen::Index i = 0; i < d.rows(); ++i) d.row(i) << std::sin(phi), 0, std::cos(phi);
  w.set_directors(d);
  const WallEnergies E = w.energies(p.X);
  const double exact = 0.5 * G * o.thickness * std::sin(phi) * std::sin(phi) * 2.0;
  EXPECT_NEAR(E.shear, exact, 1e-13 * exact);  // constant field reproduced exactly by MITC3
  EXPECT_NEAR(E.bending, 0.0, 1e-15);
  EXPECT_NEAR(E.membrane, 0.0, 1e-15);
}

TEST(Element, CylindricalBendingPinsTheBendingFactor) {
  // plate rolled isometrically onto a cylinder of radius rho with exact normals as directors:
  // E_b -> (D/2) (1/rho)^2 Area, D = E h^3 / (12 (1 - nu^2)) = G h^3 / (6 (1 - nu)).
  const double Lx = 1.0, Ly = 0.5, rho = 2.0, h = 0.01, nu = 0.3, Gs = 1.0, G = Gs / h;
  double prev_err = 1e9;
  for (int n : {8, 16}) {
    Mesh p = plate(Lx, Ly, n, n / 2, 1);
    GsmbOptions o;
    o.thickness = h;
    o.poisson = nu;
    GsmbWall w(p.X, p.T, make_law("gh", Gs, nu), o);
    Points x = p.X, d = p.X;
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      const double t = p.X(i, 0) / rho;
      x.row(i) << rho * std::sin(t), p.X(i, 1), rho * (1 - std::cos(t));
      d.row(i) << -std::sin(t), 0, std::cos(t);
    }
    w.set_directors(d);
    const WallEnergies E = w.energies(x);
    const double Dp = G * h * h * h / (6 * (1 - nu));
    const double exact = 0.5 * Dp / (rho * rho) * Lx * Ly;
    const double err = std::abs(E.bending - exact) / exact;
    // facet (chord) error O((dx/rho)^2) ~ 1e-3 at n = 8
    EXPECT_LT(err, 4e-3) << n;
    EXPECT_LT(err, prev_err) << n;
    prev_err = err;
    EXPECT_LT(E.shear, 1e-12 * exact);  // chord . (mean of the two end normals) = 0 on every edge
  }
}
