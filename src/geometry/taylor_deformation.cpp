#include "capsflow/core/geometry/taylor_deformation.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>

namespace capsflow {

InertiaEllipsoid inertia_ellipsoid(const SurfaceMesh& mesh) {
  const VolumeMoments vm = volume_moments(mesh);
  Eigen::SelfAdjointEigenSolver<Mat3> eig(vm.second_moment);
  const Vec3 sigma = eig.eigenvalues();
  const Mat3 vec = eig.eigenvectors();
  // Assign each principal axis to the coordinate axis it is most aligned with (greedy on |cos|).
  InertiaEllipsoid out;
  out.centroid = vm.centroid;
  std::array<bool, 3> used_axis{false, false, false}, used_vec{false, false, false};
  for (int round = 0; round < 3; ++round) {
    int best_i = -1, best_k = -1;
    double best = -1;
    for (int k = 0; k < 3; ++k) {
      if (used_vec[k]) continue;
      for (int i = 0; i < 3; ++i)
        if (!used_axis[i] && std::abs(vec(i, k)) > best) best = std::abs(vec(i, k)), best_i = i, best_k = k;
    }
    used_axis[best_i] = used_vec[best_k] = true;
    out.semi_axes[best_i] = std::sqrt(5.0 * std::max(sigma[best_k], 0.0) / vm.volume);
    Vec3 dir = vec.col(best_k);
    if (dir[best_i] < 0) dir = -dir;
    out.axes.col(best_i) = dir;
  }
  return out;
}

TaylorDeformation taylor_deformation(const InertiaEllipsoid& e) {
  const Vec3& L = e.semi_axes;
  auto d = [](double a, double b) { return (a - b) / (a + b); };
  return {d(L[0], L[1]), d(L[0], L[2]), d(L[1], L[2])};
}

}  // namespace capsflow
