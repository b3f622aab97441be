#include "capsflow/core/geometry/lab_centroid.hpp"

#include <unsupported/Eigen/MatrixFunctions>

namespace capsflow {

Vec3 advance_lab_centroid(const Mat3& L, double tau, const Vec3& C, const Vec3& dc) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
  M.topLeftCorner<3, 3>() = L * tau;
  M.topRightCorner<3, 1>() = dc;
  const Eigen::Matrix4d E = M.exp();
  return E.topLeftCorner<3, 3>() * C + E.topRightCorner<3, 1>();
}

}  // namespace capsflow
