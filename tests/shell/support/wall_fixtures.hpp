#pragma once
// Shared fixtures for the shell tests: a randomly deformed GSMB wall on a small icosphere.
#include <random>

#include "capsflow/shell/director.hpp"
#include "capsflow/shell/gsmb_wall.hpp"
#include "test_meshes.hpp"

namespace capsflow::shell::testing {

/// Smooth, large deformation of the unit sphere (stretch + shear + a bump), plus small noise.
inline Points deform(const Points& X, double amp, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::Matrix3d F;
  F << 1.0 + 0.3 * amp, 0.2 * amp, 0.0, -0.1 * amp, 1.0 - 0.15 * amp, 0.1 * amp, 0.05 * amp, 0.0,
      1.0 + 0.2 * amp;
  Points x(X.rows(), 3);
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const Vec3 p = X.row(i);
    Vec3 q = F * p;
    q += amp * 0.1 * std::sin(3 * p[0]) * Vec3(0, 0, 1);
    q += amp * 0.01 * Vec3(U(rng), U(rng), U(rng));
    x.row(i) = q;
  }
  return x;
}

/// Random small director rotations (w in the nodal triads).
inline Eigen::VectorXd random_w(int n_nodes, double amp, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::VectorXd w(2 * n_nodes);
  for (int i = 0; i < 2 * n_nodes; ++i) w[i] = amp * U(rng);
  return w;
}

}  // namespace capsflow::shell::testing
