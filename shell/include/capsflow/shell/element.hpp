#pragma once
// MITC3 GSMB triangle (paper §2.3-2.6, §4.1; docs/shell.md §1–2): the element kernels.
//
// Natural coordinates (r, s), shape functions N = (1-r-s, r, s), nodes at (0,0), (1,0), (0,1).
// Reference mid-surface X, reference nodal unit directors D_p; current x and unit directors d_p.
// Inside an element D(r,s) = sum N_p D_p and d(r,s) = sum N_p d_p (not renormalised, paper Eq. 42).
// With a_a = x_{,a}, A_a = X_{,a} (constant on a flat P1 facet) the strains are the paper's
// Eq. (16)-(18), written as differences from the reference (a flat-faceted reference with nodal
// directors is stress-free):
//   gamma_ab = 1/2 (a_a.a_b - A_a.A_b)
//   chi_ab   = 1/2 (a_a.d_,b + a_b.d_,a - A_a.D_,b - A_b.D_,a)
//   zeta_a   = 1/2 (a_a.d - A_a.D)             (tensor shear E_a3: half the engineering shear)
// Energy of one element (1-point rule for membrane and bending, exact for P1; 3 edge-midpoint
// points, weights A0/3, for the quadratic assumed shear):
//   E = A0 W_s(I1, I2) + A0 (h^3/24) C^{ablm} chi_ab chi_lm + sum_gp (A0/3) (h/2) D^{al} z_a z_l
//   C^{ablm} = G (A^{al}A^{bm} + A^{am}A^{bl} + 2nu/(1-nu) A^{ab}A^{lm}),  D^{al} = 4 G A^{al}.
// The curvature tensor kappa and all coupled terms are dropped (paper §4.1).
// MITC3 assumed shear (Lee & Bathe 2004): tying values
//   tau = (z_r(1/2,0), z_s(0,1/2), z_r(1/2,1/2), z_s(1/2,1/2)),  c = tau2 - tau0 - tau3 + tau1,
//   z~_r(r,s) = tau0 + c s,   z~_s(r,s) = tau1 - c r.
// Rotation DOFs: per node a right-handed orthonormal triad (t1, t2, d); an increment
// w = w1 t1 + w2 t2 rotates d by exp([w]x), so dd/dw = T = [t1 x d, t2 x d] = [-t2, t1].
#include <array>
#include <cmath>

#include "capsflow/shell/laws.hpp"
#include "capsflow/shell/types.hpp"

namespace capsflow::shell {

/// Reference data of one element needed by the membrane part.
struct MembraneRef {
  std::array<int, 3> n{};
  double A0 = 0;              ///< reference area
  double A[3] = {0, 0, 0};    ///< reference covariant metric (rr, ss, rs)
  double B[3] = {0, 0, 0};    ///< its inverse A^{ab} (rr, ss, rs)
  double detA = 0;
};

/// Reference data of one GSMB element. Cb and Sh include A0 and the moduli, so that
/// E_bend = chi^T Cb chi (chi = (rr, ss, rs)) and E_shear = tau^T Sh tau.
struct ElementRef {
  MembraneRef m;
  double chi0[3] = {0, 0, 0};  ///< reference part: 1/2 (A_a.D_,b + A_b.D_,a)
  double tau0[4] = {0, 0, 0, 0};
  double Cb[6] = {0, 0, 0, 0, 0, 0};  ///< symmetric 3x3: 00 11 22 01 02 12
  double Sh[10] = {0};                 ///< symmetric 4x4: 00 11 22 33 01 02 03 12 13 23
};

MembraneRef make_membrane_ref(const Vec3 X[3], std::array<int, 3> nodes);
/// G = G_s / h (3-D shear modulus), nu = 3-D Poisson ratio.
ElementRef make_element_ref(const Vec3 X[3], const Vec3 D[3], std::array<int, 3> nodes, double h,
                            double G, double nu);

/// The MITC3 assumed-shear map at (r, s): z~ = M tau, M is 2x4.
inline void mitc3_shear_map(double r, double s, double M[2][4]) {
  M[0][0] = 1 - s; M[0][1] = s;     M[0][2] = s;  M[0][3] = -s;
  M[1][0] = r;     M[1][1] = 1 - r; M[1][2] = -r; M[1][3] = r;
}

namespace detail {
inline double sym3(const double* c, int i, int j) {
  static constexpr int idx[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
  return c[idx[i][j]];
}
inline double sym4(const double* c, int i, int j) {
  static constexpr int idx[4][4] = {{0, 4, 5, 6}, {4, 1, 7, 8}, {5, 7, 2, 9}, {6, 8, 9, 3}};
  return c[idx[i][j]];
}
}  // namespace detail

/// Membrane part: writes nodal forces f = d(A0 W)/dx; returns A0 W_s (0 if !want_energy).
inline double membrane_element(const MembraneRef& R, const MembraneLaw& law, const Vec3 x[3],
                               Vec3 f[3], bool want_energy = true) {
  const Vec3 ar = x[1] - x[0], as = x[2] - x[0];
  const double a[3] = {ar.dot(ar), as.dot(as), ar.dot(as)};
  const double I1 = R.B[0] * a[0] + R.B[1] * a[1] + 2.0 * R.B[2] * a[2] - 2.0;
  const double I2 = (a[0] * a[1] - a[2] * a[2]) / R.detA - 1.0;
  const double w1 = 2.0 * law.W1(I1, I2) * R.A0, w2 = 2.0 * law.W2(I1, I2) / R.detA * R.A0;
  const double Srr = w1 * R.B[0] + w2 * a[1], Sss = w1 * R.B[1] + w2 * a[0],
               Srs = w1 * R.B[2] - w2 * a[2];
  f[1] = Srr * ar + Srs * as;
  f[2] = Srs * ar + Sss * as;
  f[0] = -(f[1] + f[2]);
  return want_energy ? R.A0 * law.W(I1, I2) : 0.0;
}

/// Output of the bending + shear kernel.
struct BsOut {
  double Eb = 0, Es = 0;
  Vec3 fx[3];        ///< dE/dx_p at fixed directors
  Vec3 g[3];         ///< dE/dd_p (directors as free 3-vectors)
  double K[6][6];    ///< material theta-theta Hessian T^T (d2E/dd2) T (dofs p*2+k)
};

/// Bending + MITC3 shear part. T[p][k] = dd_p/dw_k (= -t2, t1). K is filled if want_K.
inline void bs_element(const ElementRef& R, const Vec3 x[3], const Vec3 d[3], const Vec3 T[3][2],
                       BsOut& o, bool want_K) {
  using detail::sym3;
  using detail::sym4;
  const Vec3 ar = x[1] - x[0], as = x[2] - x[0];
  const Vec3 dr = d[1] - d[0], ds = d[2] - d[0];
  const Vec3 m01 = 0.5 * (d[0] + d[1]), m02 = 0.5 * (d[0] + d[2]), m12 = 0.5 * (d[1] + d[2]);
  double chi[3] = {ar.dot(dr) - R.chi0[0], as.dot(ds) - R.chi0[1],
                   0.5 * (ar.dot(ds) + as.dot(dr)) - R.chi0[2]};
  double tau[4] = {0.5 * ar.dot(m01) - R.tau0[0], 0.5 * as.dot(m02) - R.tau0[1],
                   0.5 * ar.dot(m12) - R.tau0[2], 0.5 * as.dot(m12) - R.tau0[3]};
  double m[3], p[4];
  for (int i = 0; i < 3; ++i) m[i] = 2.0 * (sym3(R.Cb, i, 0) * chi[0] + sym3(R.Cb, i, 1) * chi[1] + sym3(R.Cb, i, 2) * chi[2]);
  for (int i = 0; i < 4; ++i)
    p[i] = 2.0 * (sym4(R.Sh, i, 0) * tau[0] + sym4(R.Sh, i, 1) * tau[1] + sym4(R.Sh, i, 2) * tau[2] + sym4(R.Sh, i, 3) * tau[3]);
  o.Eb = 0.5 * (m[0] * chi[0] + m[1] * chi[1] + m[2] * chi[2]);
  o.Es = 0.5 * (p[0] * tau[0] + p[1] * tau[1] + p[2] * tau[2] + p[3] * tau[3]);
  const Vec3 dEdar = m[0] * dr + 0.5 * m[2] * ds + 0.5 * (p[0] * m01 + p[2] * m12);
  const Vec3 dEdas = m[1] * ds + 0.5 * m[2] * dr + 0.5 * (p[1] * m02 + p[3] * m12);
  o.fx[1] = dEdar;
  o.fx[2] = dEdas;
  o.fx[0] = -(dEdar + dEdas);
  const Vec3 dEddr = m[0] * ar + 0.5 * m[2] * as, dEdds = m[1] * as + 0.5 * m[2] * ar;
  const Vec3 g01 = 0.5 * p[0] * ar, g02 = 0.5 * p[1] * as, g12 = 0.5 * (p[2] * ar + p[3] * as);
  o.g[0] = -(dEddr + dEdds) + 0.5 * (g01 + g02);
  o.g[1] = dEddr + 0.5 * (g01 + g12);
  o.g[2] = dEdds + 0.5 * (g02 + g12);
  if (!want_K) return;
  static constexpr double Nr[3] = {-1, 1, 0}, Ns[3] = {-1, 0, 1};
  static constexpr double w01[3] = {0.5, 0.5, 0}, w02[3] = {0.5, 0, 0.5}, w12[3] = {0, 0.5, 0.5};
  double Bc[3][6], Bt[4][6];
  for (int pn = 0; pn < 3; ++pn)
    for (int k = 0; k < 2; ++k) {
      const int c = 2 * pn + k;
      const double arv = ar.dot(T[pn][k]), asv = as.dot(T[pn][k]);
      Bc[0][c] = Nr[pn] * arv;
      Bc[1][c] = Ns[pn] * asv;
      Bc[2][c] = 0.5 * (Ns[pn] * arv + Nr[pn] * asv);
      Bt[0][c] = 0.5 * arv * w01[pn];
      Bt[1][c] = 0.5 * asv * w02[pn];
      Bt[2][c] = 0.5 * arv * w12[pn];
      Bt[3][c] = 0.5 * asv * w12[pn];
    }
  double CB[3][6], SB[4][6];
  for (int i = 0; i < 3; ++i)
    for (int c = 0; c < 6; ++c)
      CB[i][c] = 2.0 * (sym3(R.Cb, i, 0) * Bc[0][c] + sym3(R.Cb, i, 1) * Bc[1][c] + sym3(R.Cb, i, 2) * Bc[2][c]);
  for (int i = 0; i < 4; ++i)
    for (int c = 0; c < 6; ++c)
      SB[i][c] = 2.0 * (sym4(R.Sh, i, 0) * Bt[0][c] + sym4(R.Sh, i, 1) * Bt[1][c] +
                        sym4(R.Sh, i, 2) * Bt[2][c] + sym4(R.Sh, i, 3) * Bt[3][c]);
  for (int a = 0; a < 6; ++a)
    for (int b = a; b < 6; ++b) {
      const double v = Bc[0][a] * CB[0][b] + Bc[1][a] * CB[1][b] + Bc[2][a] * CB[2][b] +
                       Bt[0][a] * SB[0][b] + Bt[1][a] * SB[1][b] + Bt[2][a] * SB[2][b] + Bt[3][a] * SB[3][b];
      o.K[a][b] = v;
      o.K[b][a] = v;
    }
}

/// Element energy, templated on the scalar (double, or automatic-differentiation types) for
/// tests and for the forward static mode. x and d are 3 nodes x 3 components. out = (Wm, Eb, Es).
template <class S>
void element_energy_t(const ElementRef& R, const MembraneLaw& law, const S x[3][3], const S d[3][3],
                      S out[3]) {
  S ar[3], as[3], dr[3], ds[3], m01[3], m02[3], m12[3];
  for (int i = 0; i < 3; ++i) {
    ar[i] = x[1][i] - x[0][i]; as[i] = x[2][i] - x[0][i];
    dr[i] = d[1][i] - d[0][i]; ds[i] = d[2][i] - d[0][i];
    m01[i] = 0.5 * (d[0][i] + d[1][i]); m02[i] = 0.5 * (d[0][i] + d[2][i]); m12[i] = 0.5 * (d[1][i] + d[2][i]);
  }
  auto dot = [](const S* u, const S* v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
  const S arr = dot(ar, ar), ass = dot(as, as), ars = dot(ar, as);
  const MembraneRef& M = R.m;
  const S I1 = M.B[0] * arr + M.B[1] * ass + 2.0 * M.B[2] * ars - 2.0;
  const S I2 = (arr * ass - ars * ars) / M.detA - 1.0;
  out[0] = M.A0 * law.W_t(I1, I2);
  S chi[3] = {dot(ar, dr) - R.chi0[0], dot(as, ds) - R.chi0[1],
              0.5 * (dot(ar, ds) + dot(as, dr)) - R.chi0[2]};
  S tau[4] = {0.5 * dot(ar, m01) - R.tau0[0], 0.5 * dot(as, m02) - R.tau0[1],
              0.5 * dot(ar, m12) - R.tau0[2], 0.5 * dot(as, m12) - R.tau0[3]};
  S eb = S(0.0), es = S(0.0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) eb = eb + detail::sym3(R.Cb, i, j) * chi[i] * chi[j];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) es = es + detail::sym4(R.Sh, i, j) * tau[i] * tau[j];
  out[1] = eb;
  out[2] = es;
}

}  // namespace capsflow::shell
