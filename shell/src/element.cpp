#include "capsflow/shell/element.hpp"

#include <stdexcept>

namespace capsflow::shell {

MembraneRef make_membrane_ref(const Vec3 X[3], std::array<int, 3> nodes) {
  MembraneRef R;
  R.n = nodes;
  const Vec3 Ar = X[1] - X[0], As = X[2] - X[0];
  R.A[0] = Ar.dot(Ar);
  R.A[1] = As.dot(As);
  R.A[2] = Ar.dot(As);
  R.detA = R.A[0] * R.A[1] - R.A[2] * R.A[2];
  if (!(R.detA > 0)) throw std::invalid_argument("shell: degenerate reference triangle");
  R.B[0] = R.A[1] / R.detA;
  R.B[1] = R.A[0] / R.detA;
  R.B[2] = -R.A[2] / R.detA;
  R.A0 = 0.5 * std::sqrt(R.detA);
  return R;
}

namespace {
// bilinear form C^{ablm} x_ab y_lm / G for symmetric 2x2 tensors given as (rr, ss, rs)
double cform(const double B[3], const double x[3], const double y[3], double nu) {
  const double Bm[2][2] = {{B[0], B[2]}, {B[2], B[1]}};
  const double X[2][2] = {{x[0], x[2]}, {x[2], x[1]}};
  const double Y[2][2] = {{y[0], y[2]}, {y[2], y[1]}};
  double t1 = 0, trx = 0, tr_y = 0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) {
      trx += Bm[a][b] * X[a][b];
      tr_y += Bm[a][b] * Y[a][b];
      for (int l = 0; l < 2; ++l)
        for (int m = 0; m < 2; ++m) t1 += (Bm[a][l] * Bm[b][m] + Bm[a][m] * Bm[b][l]) * X[a][b] * Y[l][m];
    }
  return t1 + 2.0 * nu / (1.0 - nu) * trx * tr_y;
}
}  // namespace

ElementRef make_element_ref(const Vec3 X[3], const Vec3 D[3], std::array<int, 3> nodes, double h,
                            double G, double nu) {
  ElementRef R;
  R.m = make_membrane_ref(X, nodes);
  const Vec3 Ar = X[1] - X[0], As = X[2] - X[0];
  const Vec3 Dr = D[1] - D[0], Ds = D[2] - D[0];
  R.chi0[0] = Ar.dot(Dr);
  R.chi0[1] = As.dot(Ds);
  R.chi0[2] = 0.5 * (Ar.dot(Ds) + As.dot(Dr));
  const Vec3 m01 = 0.5 * (D[0] + D[1]), m02 = 0.5 * (D[0] + D[2]), m12 = 0.5 * (D[1] + D[2]);
  R.tau0[0] = 0.5 * Ar.dot(m01);
  R.tau0[1] = 0.5 * As.dot(m02);
  R.tau0[2] = 0.5 * Ar.dot(m12);
  R.tau0[3] = 0.5 * As.dot(m12);
  // bending: E = A0 (h^3/24) G cform(chi, chi)
  const double e[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const double cb = R.m.A0 * h * h * h / 24.0 * G;
  double C3[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) C3[i][j] = cb * cform(R.m.B, e[i], e[j], nu);
  R.Cb[0] = C3[0][0]; R.Cb[1] = C3[1][1]; R.Cb[2] = C3[2][2];
  R.Cb[3] = C3[0][1]; R.Cb[4] = C3[0][2]; R.Cb[5] = C3[1][2];
  // shear: E = sum_gp (A0/3) (h/2) 4G B^{al} z_a z_l,  z = M_gp tau
  const double gp[3][2] = {{0.5, 0.0}, {0.5, 0.5}, {0.0, 0.5}};
  const double Bm[2][2] = {{R.m.B[0], R.m.B[2]}, {R.m.B[2], R.m.B[1]}};
  double S4[4][4] = {};
  for (auto& q : gp) {
    double M[2][4];
    mitc3_shear_map(q[0], q[1], M);
    const double w = R.m.A0 / 3.0 * 0.5 * h * 4.0 * G;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        for (int a = 0; a < 2; ++a)
          for (int l = 0; l < 2; ++l) S4[i][j] += w * M[a][i] * Bm[a][l] * M[l][j];
  }
  R.Sh[0] = S4[0][0]; R.Sh[1] = S4[1][1]; R.Sh[2] = S4[2][2]; R.Sh[3] = S4[3][3];
  R.Sh[4] = S4[0][1]; R.Sh[5] = S4[0][2]; R.Sh[6] = S4[0][3];
  R.Sh[7] = S4[1][2]; R.Sh[8] = S4[1][3]; R.Sh[9] = S4[2][3];
  return R;
}

}  // namespace capsflow::shell
