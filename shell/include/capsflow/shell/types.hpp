#pragma once
// Basic types shared by the shell library (capsflow::shell).
//
// Conventions (whole library):
//  * Points: N x 3 row-major node coordinates (same type as capsflow::core's).
//  * Triangles: M x 3 node indices, counter-clockwise seen from outside (outward normal
//    n = (x1 - x0) x (x2 - x0) / |..|).
//  * Non-dimensional units of the project: lengths by l, G_s = 1/Ca_s, thickness h = alpha,
//    G = G_s / h, nu = nu_s. Forces R_s are nodal (energy per length), loads q per deformed area.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace capsflow::shell {

using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Triangles = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Vec3 = Eigen::Vector3d;

/// Total wall energies (paper Eq. 31 with the 1/2 of a quadratic energy):
/// membrane = sum A0 W_s(gamma), bending = sum A0 (h^3/24) C chi chi, shear = sum A0 (h/2) D zeta zeta.
struct WallEnergies {
  double membrane = 0, bending = 0, shear = 0;
  double total() const { return membrane + bending + shear; }
};

/// Statistics of one forces() call (rotation solve). For a membrane wall everything stays 0.
struct WallStats {
  int newton_iterations = 0;  ///< Newton corrections applied (0 = warm start already converged)
  int cg_iterations = 0;      ///< CG iterations summed over the Newton corrections
  double residual = 0;        ///< final max_i |R_theta,i| / K_ii (radians; see GsmbOptions::newton_tol)
  bool converged = true;
};

}  // namespace capsflow::shell
