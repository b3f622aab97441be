// Walls: rotation solve, global invariants, determinism, restart, inflated sphere (Laplace law),
// load recovery.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <vector>

#include "capsflow/shell/load_recovery.hpp"
#include "support/wall_fixtures.hpp"

using namespace capsflow::shell;
using namespace capsflow::shell::testing;

namespace {
double maxabs(const Points& p) { return p.cwiseAbs().maxCoeff(); }
Points rotated(const Points& x, const Eigen::Matrix3d& Q) {
  Points y = x;
  for (Eigen::Index i = 0; i < x.rows(); ++i) y.row(i) = (Q * Vec3(x.row(i))).transpose();
  return y;
}
GsmbOptions opts(double h) {
  GsmbOptions o;
  o.thickness = h;
  o.poisson = 0.5;
  return o;
}
}  // namespace

TEST(RotationSolve, ConvergesFromReferenceAndFromWarmStart) {
  Mesh m = icosphere(3);
  GsmbWall w(m.X, m.T, make_law("nh", 1.0), opts(0.05));
  const Points x = deform(m.X, 1.0, 1);
  Points R;
  WallStats st;
  w.forces(x, R, &st);
  EXPECT_TRUE(st.converged);
  EXPECT_LE(st.residual, 1e-10);
  EXPECT_LE(st.newton_iterations, 8);  // large deformation from the reference directors
  // one small step (as one RK stage): x + 1e-4 * (smooth velocity field)
  Points x2 = x;
  for (Eigen::Index i = 0; i < x.rows(); ++i) x2.row(i) += 1e-4 * Vec3(x(i, 2), 0.3 * x(i, 0), -x(i, 0)).transpose();
  w.forces(x2, R, &st);
  EXPECT_TRUE(st.converged);
  EXPECT_LE(st.newton_iterations, 2);  // warm start: quadratic convergence from O(1e-4) rad
  std::printf("warm start: newton %d cg %d residual %.2e\n", st.newton_iterations, st.cg_iterations, st.residual);
}

TEST(RotationSolve, TraceReportsEveryNewtonStep) {
  Mesh m = icosphere(3);
  GsmbWall w(m.X, m.T, make_law("nh", 1.0), opts(0.05));
  std::vector<NewtonStep> steps;
  w.set_trace([&](const NewtonStep& s) { steps.push_back(s); });
  Points R;
  WallStats st;
  w.forces(deform(m.X, 1.0, 1), R, &st);  // a cold solve: several corrections
  ASSERT_TRUE(st.converged);
  ASSERT_GE(st.newton_iterations, 2);
  // one entry per residual evaluation: each correction, then the converged residual
  ASSERT_EQ(static_cast<int>(steps.size()), st.newton_iterations + 1);
  int cg = 0;
  for (int k = 0; k < static_cast<int>(steps.size()); ++k) {
    EXPECT_EQ(steps[k].iteration, k);
    cg += steps[k].cg_iterations;
    if (k + 1 < static_cast<int>(steps.size())) {
      EXPECT_GT(steps[k].cg_iterations, 0);
      EXPECT_LE(steps[k].cg_relres, w.options().cg_tol);  // each correction solved to cg_tol
    }
  }
  EXPECT_EQ(cg, st.cg_iterations);
  EXPECT_EQ(steps.back().cg_iterations, 0);            // converged: no correction follows
  EXPECT_EQ(steps.back().residual, st.residual);        // the same number, not a recomputation
  EXPECT_LE(steps.back().residual, w.options().newton_tol);
  EXPECT_GT(steps.front().residual, 1e3 * steps.back().residual);  // a cold start is far from it
}

TEST(RotationSolve, LargeRigidRotationIsExact) {
  Mesh m = icosphere(2);
  GsmbWall w(m.X, m.T, make_law("skalak", 1.0, 0, 1.0), opts(0.1));
  const Points x = deform(m.X, 0.8, 2);
  Points R0, R1;
  w.forces(x, R0);
  // rotate positions by 2.7 rad but keep the old directors as the warm start (far from equilibrium)
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(2.7, Vec3(1, 2, -0.5).normalized()).toRotationMatrix();
  WallStats st;
  w.forces(rotated(x, Q), R1, &st);
  EXPECT_TRUE(st.converged) << st.newton_iterations;
  const Points QR0 = rotated(R0, Q);
  // both states converged to newton_tol = 1e-10 rad: forces agree to ~1e-8 relative
  EXPECT_LT(maxabs(R1 - QR0), 1e-8 * maxabs(R0));
  const Points Qd = rotated(w.directors(), Eigen::Matrix3d::Identity());
  std::printf("rigid rotation 2.7 rad: newton %d cg %d\n", st.newton_iterations, st.cg_iterations);
}

TEST(Wall, GlobalInvariantsOfTheNodalForces) {
  Mesh m = icosphere(3);
  GsmbWall w(m.X, m.T, make_law("gh", 1.0, 0.4), opts(0.05));
  const Points x = deform(m.X, 1.0, 4);
  Points R;
  w.forces(x, R);
  double sabs = 0, mabs = 0;
  Vec3 F = Vec3::Zero(), Mx = Vec3::Zero(), Md = Vec3::Zero();
  const Points& g = w.director_forces();
  const Points& d = w.directors();
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    F += Vec3(R.row(i));
    Mx += Vec3(x.row(i)).cross(Vec3(R.row(i)));
    Md += Vec3(d.row(i)).cross(Vec3(g.row(i)));
    sabs += R.row(i).norm();
    mabs += x.row(i).norm() * R.row(i).norm();
  }
  EXPECT_LT(F.norm(), 1e-14 * sabs);          // each element's forces sum to zero exactly: round-off
  EXPECT_LT((Mx + Md).norm(), 1e-14 * mabs);  // rotation invariance of E(x, d): round-off
  // at rotational equilibrium g_i || d_i, so sum x x R_s = 0 up to the Newton tolerance
  EXPECT_LT(Mx.norm(), 1e-9 * mabs);
  std::printf("|sum R| %.2e  |sum x x R| %.2e  (scale %.2e)\n", F.norm(), Mx.norm(), mabs);
  // membrane wall: exact to round-off
  MembraneWall mw(m.X, m.T, make_law("nh", 1.0));
  mw.forces(x, R);
  Mx.setZero();
  F.setZero();
  mabs = 0;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    F += Vec3(R.row(i));
    Mx += Vec3(x.row(i)).cross(Vec3(R.row(i)));
    mabs += x.row(i).norm() * R.row(i).norm();
  }
  EXPECT_LT(F.norm(), 1e-14 * mabs);
  EXPECT_LT(Mx.norm(), 1e-14 * mabs);
  // int q dS = 0 through the consistent mass matrix
  LoadRecovery lr(m.T, m.X.rows());
  Points q;
  lr.solve(x, R, q);
  const SpMatR& M = lr.mass();
  Vec3 Q = Vec3::Zero();
  Eigen::VectorXd one = Eigen::VectorXd::Ones(x.rows());
  for (int c = 0; c < 3; ++c) Q[c] = one.dot(M * q.col(c));
  EXPECT_LT(Q.norm(), 1e-12 * sabs);  // 1^T M q = sum R = 0 up to the CG tolerance 1e-12
}

TEST(Wall, MembraneForcesAreTheColourOrderedSumForAnyThreadCount) {
  // 20 480 elements: above kParallelMembranePass, so 2 threads run the one-team pass. Reference:
  // the elements added into the nodes colour by colour, in element order within a colour (the
  // serial assembly the pass replaces); each node then sums in the same order, so the forces must
  // agree bit for bit (tolerance 0: the property under test is the summation order).
  Mesh m = icosphere(5);
  const Points x = deform(m.X, 0.8, 7);
  const MembraneLaw law = make_law("sk", 1.0, 0.5, 1.0);
  MembraneWall w(m.X, m.T, law);
  const Topology& topo = w.topology();
  Points ref = Points::Zero(x.rows(), 3);
  for (const auto& col : topo.colors)
    for (const int e : col) {
      const auto& t = topo.tri[e];
      const Vec3 X[3] = {m.X.row(t[0]), m.X.row(t[1]), m.X.row(t[2])};
      const MembraneRef R = make_membrane_ref(X, t);
      const Vec3 xe[3] = {x.row(t[0]), x.row(t[1]), x.row(t[2])};
      Vec3 f[3];
      membrane_element(R, law, xe, f, false);
      for (int a = 0; a < 3; ++a) ref.row(t[a]) += f[a].transpose();
    }
  const int nt = omp_get_max_threads();
  for (const int threads : {1, 2}) {
    omp_set_num_threads(threads);
    Points R;
    w.forces(x, R);
    EXPECT_EQ((R - ref).cwiseAbs().maxCoeff(), 0.0) << threads << " threads";
  }
  omp_set_num_threads(nt);
}

TEST(Wall, DeterministicAcrossThreadCountsAndRestartable) {
  // 5 120 elements: above every team threshold of parallel_thresholds.hpp (element pass, both
  // PCGs, the mass assembly), so the 2-thread runs use every parallel path.
  Mesh m = icosphere(4);
  const Points x = deform(m.X, 1.0, 6);
  const int nt = omp_get_max_threads();
  Points R1, R2, R3;
  {
    omp_set_num_threads(1);
    GsmbWall w(m.X, m.T, make_law("nh", 1.0), opts(0.03));
    w.forces(x, R1);
  }
  Eigen::VectorXd s;
  {
    omp_set_num_threads(std::max(2, nt));
    GsmbWall w(m.X, m.T, make_law("nh", 1.0), opts(0.03));
    w.forces(x, R2);
    s = w.state();
    Points x2 = x * 1.001;
    w.forces(x2, R3);
  }
  Points q1, q2;
  {
    LoadRecovery lr(m.T, m.X.rows());
    omp_set_num_threads(1);
    lr.solve(x, R1, q1);
    omp_set_num_threads(std::max(2, nt));
    lr.solve(x, R1, q2);
  }
  omp_set_num_threads(nt);
  EXPECT_EQ((R1 - R2).cwiseAbs().maxCoeff(), 0.0);  // bit-identical (fixed summation order)
  EXPECT_EQ((q1 - q2).cwiseAbs().maxCoeff(), 0.0);  // load recovery: fixed-chunk reductions
  GsmbWall w2(m.X, m.T, make_law("nh", 1.0), opts(0.03));
  w2.set_state(s);
  Points R4;
  w2.forces(x * 1.001, R4);
  EXPECT_EQ((R3 - R4).cwiseAbs().maxCoeff(), 0.0);  // restart from state() is bit-for-bit
}

TEST(Wall, InflatedSphereFollowsLaplaceLaw) {
  // Uniform radial stretch lambda of the unit sphere: exact load q = 2 T(lambda) / lambda, outward.
  // (1) Weak form: sum_i R_i . psi(x_i) = int q_h . psi_h dS against psi = (1 + x1^2/lambda^2) n
  //     must converge at O(h^2) to q lambda^2 (4 pi + 4 pi / 3).
  // (2) Pointwise q from the consistent mass: converges at nodes >= 3 rings away from the 12
  //     valence-5 vertices of the icosphere; AT those vertices the P1 load has an O(1) error that
  //     does not decrease with refinement (measured 0.34 consistent, 0.14 lumped: a property of
  //     the discrete mean curvature of P1 facets at irregular vertices, not of the law).
  for (const char* name : {"nh", "skalak", "gh"}) {
    const MembraneLaw law = make_law(name, 1.0, 0.4, 1.0);
    const double lam = 1.2;
    double T, T2;
    law.principal_tensions(lam, lam, T, T2);
    const double q_exact = 2 * T / lam;
    const double weak_exact = q_exact * lam * lam * (4 * M_PI + 4 * M_PI / 3);
    double prev = 1e9;
    for (int level : {2, 3, 4}) {
      Mesh m = icosphere(level);
      const Points x = lam * m.X;
      LoadRecovery lr(m.T, m.X.rows());
      for (int model = 0; model < 2; ++model) {
        Points R, q;
        if (model == 0) {
          MembraneWall w(m.X, m.T, law);
          w.forces(x, R);
        } else {
          // thin GSMB wall with analytic reference normals: bending adds O(h^2) = 1e-6 relative
          GsmbWall w(m.X, m.T, m.X, law, opts(1e-3));
          w.forces(x, R);
        }
        lr.solve(x, R, q);
        double weak = 0, err_far = 0, err_v5 = 0;
        const Topology topo(m.T, m.X.rows());
        std::vector<int> ring(x.rows(), 99);
        for (int i = 0; i < x.rows(); ++i)
          if (topo.inc_ptr[i + 1] - topo.inc_ptr[i] == 5) ring[i] = 0;
        for (int r = 0; r < 3; ++r)
          for (int i = 0; i < x.rows(); ++i)
            if (ring[i] == r)
              for (int p = topo.adj_ptr[i]; p < topo.adj_ptr[i + 1]; ++p)
                ring[topo.adj[p]] = std::min(ring[topo.adj[p]], r + 1);
        for (Eigen::Index i = 0; i < x.rows(); ++i) {
          const Vec3 p = x.row(i), n = p.normalized();
          weak += Vec3(R.row(i)).dot(n) * (1 + p[0] * p[0] / (lam * lam));
          const double e = std::abs(Vec3(q.row(i)).dot(n) - q_exact) / q_exact;
          if (ring[i] >= 3) err_far = std::max(err_far, e);
          if (ring[i] == 0) err_v5 = std::max(err_v5, e);
        }
        const double werr = std::abs(weak - weak_exact) / weak_exact;
        // measured 1.88e-2, 4.77e-3, 1.20e-3 (levels 2-4, all laws): bound 1.1x measured
        const double wtol = level == 2 ? 2.1e-2 : (level == 3 ? 5.3e-3 : 1.35e-3);
        EXPECT_LT(werr, wtol) << name << level << " model " << model;
        if (model == 0) {
          EXPECT_LT(werr, prev / 3.8) << name << level;  // second order: ratio 4 per level
          prev = werr;
          std::printf("%s level %d: weak %.3e  pointwise far %.3e  at valence-5 %.3e\n", name, level,
                      werr, err_far, err_v5);
        }
        if (level == 4) {
          EXPECT_LT(err_far, 1e-2) << name << " model " << model;  // measured 5.5e-3
          EXPECT_LT(err_v5, 0.36) << name << " model " << model;   // documented O(1) defect, measured 0.34
        }
      }
    }
  }
}

TEST(Wall, EnergyMapsOfUniformStretch) {
  Mesh m = icosphere(2);
  const MembraneLaw law = make_law("nh", 1.0);
  const double lam = 1.1;
  MembraneWall w(m.X, m.T, law);
  Eigen::VectorXd Em, Eb, Es;
  w.nodal_energy_maps(lam * m.X, Em, Eb, Es);
  const double W = law.W(2 * lam * lam - 2, std::pow(lam, 4) - 1);
  EXPECT_LT((Em.array() - W).abs().maxCoeff(), 1e-13);  // every element has W exactly
  const WallEnergies E = w.energies(lam * m.X);
  double area = 0;
  for (Eigen::Index e = 0; e < m.T.rows(); ++e)
    area += 0.5 * (Vec3(m.X.row(m.T(e, 1)) - m.X.row(m.T(e, 0))).cross(Vec3(m.X.row(m.T(e, 2)) - m.X.row(m.T(e, 0))))).norm();
  EXPECT_NEAR(E.membrane, W * area, 1e-12 * W * area);
}

TEST(LoadRecovery, ReproducesConstantLoadAndConverges) {
  Mesh m = icosphere(4);
  const Points x = deform(m.X, 1.0, 9);
  LoadRecovery lr(m.T, m.X.rows());
  const SpMatR& M = lr.assemble(x);
  Points c(x.rows(), 3);
  for (Eigen::Index i = 0; i < x.rows(); ++i) c.row(i) << 1.0, -2.0, 0.5;
  Points R(x.rows(), 3);
  for (int k = 0; k < 3; ++k) R.col(k) = M * c.col(k);
  Points q;
  const int it = lr.solve(x, R, q, 1e-12);
  EXPECT_LE(it, 40);  // Jacobi-preconditioned consistent mass: cond <= ~4, ~15-25 iterations
  EXPECT_LT(maxabs(q - c), 1e-10);  // cond(M) ~ 10 times the 1e-12 residual tolerance
  EXPECT_LE(lr.last_relative_residual(), 1e-12);
  // lumped: exact for a constant field only if R is the row sum (here it is: M c = lumped c)
  Points ql;
  lr.solve_lumped(x, R, ql);
  EXPECT_LT(maxabs(ql - c), 1e-12);
}

TEST(Wall, ForcesAreTheTotalDerivativeOfTheRotationMinimisedEnergy) {
  // E*(x) = min_theta E(x, theta); at R_theta = 0, R_s = dE*/dx. Central differences of E*, each
  // evaluation re-solving the rotations (error in E* from newton_tol 1e-10 is O(1e-20): negligible).
  Mesh m = icosphere(2);
  GsmbWall w(m.X, m.T, make_law("nh", 1.0), opts(0.08));
  const Points x = deform(m.X, 0.7, 12);
  Points R, tmp;
  w.forces(x, R);
  const Eigen::VectorXd s0 = w.state();
  auto Estar = [&](const Points& y) {
    w.set_state(s0);
    w.forces(y, tmp);
    return w.energies(y).total();
  };
  const double h = 1e-6;
  double worst = 0;
  for (Eigen::Index i = 0; i < x.rows(); i += 7)
    for (int c = 0; c < 3; ++c) {
      Points xp = x, xm = x;
      xp(i, c) += h;
      xm(i, c) -= h;
      worst = std::max(worst, std::abs((Estar(xp) - Estar(xm)) / (2 * h) - R(i, c)));
    }
  EXPECT_LT(worst, 1e-6 * maxabs(R));  // FD error budget as in the element tests
  // membrane-only wall: R_s against differences of the membrane energy
  MembraneWall mw(m.X, m.T, make_law("skalak", 1.0, 0, 2.0));
  mw.forces(x, R);
  worst = 0;
  for (Eigen::Index i = 0; i < x.rows(); i += 5)
    for (int c = 0; c < 3; ++c) {
      Points xp = x, xm = x;
      xp(i, c) += h;
      xm(i, c) -= h;
      worst = std::max(worst, std::abs((mw.energies(xp).membrane - mw.energies(xm).membrane) / (2 * h) - R(i, c)));
    }
  EXPECT_LT(worst, 1e-6 * maxabs(R));
}

TEST(Wall, PreInflatedSphereLoadPointsOutward) {
  // sign convention: a stretched capsule has q outward, so v = v_inf - S[q] shrinks it
  Mesh m = icosphere(3);
  GsmbWall w(m.X, m.T, make_law("gh", 1.0, 0.3), opts(0.05));
  const Points x = 1.05 * m.X;
  Points R, q;
  w.forces(x, R);
  LoadRecovery lr(m.T, m.X.rows());
  lr.solve(x, R, q);
  int inward = 0;
  for (Eigen::Index i = 0; i < x.rows(); ++i) inward += Vec3(q.row(i)).dot(Vec3(x.row(i))) <= 0;
  EXPECT_EQ(inward, 0);
}

TEST(RotationSolve, FollowsAFullTankTreadingTurn) {
  // Deformed wall rotated rigidly about an axis in 100 increments of 2 pi / 100 (as tank-treading
  // does over a run): every stage converges in <= 3 Newton corrections (normal predictor + warm
  // start), triads stay orthonormal, and after a full turn the forces are those of the start.
  Mesh m = icosphere(2);
  GsmbWall w(m.X, m.T, make_law("nh", 1.0), opts(0.05));
  const Points x0 = deform(m.X, 0.6, 21);
  Points R0, R;
  w.forces(x0, R0);
  const Vec3 axis = Vec3(0.2, 1.0, 0.3).normalized();
  int worst_newton = 0;
  for (int k = 1; k <= 100; ++k) {
    const Eigen::Matrix3d Q = Eigen::AngleAxisd(2 * M_PI * k / 100, axis).toRotationMatrix();
    WallStats st;
    w.forces(rotated(x0, Q), R, &st);
    ASSERT_TRUE(st.converged) << k;
    worst_newton = std::max(worst_newton, st.newton_iterations);
  }
  EXPECT_LE(worst_newton, 3);  // 3.6 deg per stage: ~600x the rotation of a real RK stage (gamma_dot dt = 1e-4)
  const Eigen::Matrix3d Qf = Eigen::AngleAxisd(2 * M_PI, axis).toRotationMatrix();
  EXPECT_LT(maxabs(R - rotated(R0, Qf)), 1e-8 * maxabs(R0));  // both converged to 1e-10 rad
  double orth = 0;
  for (Eigen::Index i = 0; i < x0.rows(); ++i) {
    const Vec3 d = w.directors().row(i), a = w.t1().row(i), b = w.t2().row(i);
    orth = std::max({orth, std::abs(d.norm() - 1), std::abs(a.dot(d)), std::abs(b.dot(d)), std::abs(a.dot(b)),
                     (a.cross(b) - d).norm()});
  }
  EXPECT_LT(orth, 1e-14);  // re-orthonormalised at every update
}

TEST(Wall, GsmbEnergyMapsSumToTheEnergies) {
  // Em_i = (sum of element energies around i) / (sum of their reference areas S_i), so
  // sum_i Em_i S_i = 3 E (each element is counted at its 3 nodes); same for Eb and Esh.
  Mesh m = icosphere(2);
  GsmbWall w(m.X, m.T, make_law("skalak", 1.0, 0, 1.0), opts(0.1));
  const Points x = deform(m.X, 0.8, 31);
  Points R;
  w.forces(x, R);
  Eigen::VectorXd Em, Eb, Es;
  w.nodal_energy_maps(x, Em, Eb, Es);
  const WallEnergies E = w.energies(x);
  const Topology& t = w.topology();
  double sm = 0, sb = 0, ss = 0;
  for (int i = 0; i < t.n_nodes; ++i) {
    double S = 0;
    for (int p = t.inc_ptr[i]; p < t.inc_ptr[i + 1]; ++p) S += w.elements()[t.inc_elem[p]].m.A0;
    sm += Em[i] * S;
    sb += Eb[i] * S;
    ss += Es[i] * S;
  }
  EXPECT_NEAR(sm, 3 * E.membrane, 1e-12 * E.membrane);  // round-off of sums of ~300 terms
  EXPECT_NEAR(sb, 3 * E.bending, 1e-12 * E.bending);
  EXPECT_NEAR(ss, 3 * E.shear, 1e-12 * E.shear);
  EXPECT_GT(E.bending, 0.0);
  EXPECT_GT(E.shear, 0.0);
}
