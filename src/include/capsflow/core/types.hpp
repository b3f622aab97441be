#pragma once
// Basic array types shared across capsflow::core.
// Points are row-major N×3 so that data() is x0,y0,z0,x1,... — the layout capsflow::fmm takes.
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

namespace capsflow {

using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Triangles = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// A closed triangulated surface. Triangles are oriented counter-clockwise seen from outside
// (outward normals by the right-hand rule).
struct SurfaceMesh {
  Points vertices;
  Triangles triangles;
  Eigen::Index num_nodes() const { return vertices.rows(); }
  Eigen::Index num_elements() const { return triangles.rows(); }
};

}  // namespace capsflow
