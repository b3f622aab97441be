// Geometry diagnostics against exact values: the solver's P1 mass matrix (shell::LoadRecovery)
// against core's areas, volume moments of a box-like polyhedron, Taylor deformation, extents.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/geometry/taylor_deformation.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/shell/load_recovery.hpp"

using namespace capsflow;

TEST(MassMatrix, SymmetricPositiveTotalAreaRowSumsOnCurrentSurface) {
  SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 2);
  // Move the surface (non-affine) so that the current areas differ from the reference ones.
  for (Eigen::Index i = 0; i < m.num_nodes(); ++i) {
    const Vec3 x = m.vertices.row(i);
    m.vertices.row(i) = (x + Vec3(0.3 * x[1] * x[1], -0.2 * x[0] * x[2], 0.5 * x[2])).transpose();
  }
  shell::LoadRecovery mass(m.triangles, m.num_nodes());
  const Eigen::SparseMatrix<double> M = mass.assemble(m.vertices);
  const Eigen::MatrixXd D = Eigen::MatrixXd(M);
  EXPECT_LT((D - D.transpose()).cwiseAbs().maxCoeff(), 1e-15);  // assembled from symmetric blocks: exact
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(D);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0);  // P1 mass matrix is SPD on a non-degenerate mesh
  // 1ᵀ M 1 = ∫ 1 dS and M 1 = nodal areas, on the current surface (sums of exact element terms).
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(m.num_nodes());
  EXPECT_NEAR(ones.dot(M * ones), surface_area(m), 1e-12 * surface_area(m));
  EXPECT_LT((M * ones - nodal_areas(m)).cwiseAbs().maxCoeff(), 1e-14);
  // And it is not the reference-surface matrix.
  const SurfaceMesh ref = make_sphere_mesh(BaseSolid::Icosahedron, 2);
  const Eigen::SparseMatrix<double> M_ref = mass.assemble(ref.vertices);
  EXPECT_GT(std::abs(ones.dot(M_ref * ones) - surface_area(m)), 0.1);
}

TEST(VolumeMoments, UnitCubeExact) {
  // A cube [0,1]^3 triangulated outward: V = 1, centroid 0.5, central second moment I/12.
  SurfaceMesh c;
  c.vertices.resize(8, 3);
  c.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1;
  c.triangles.resize(12, 3);
  c.triangles << 0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7;
  const VolumeMoments vm = volume_moments(c);
  EXPECT_NEAR(vm.volume, 1.0, 1e-15);  // exact arithmetic on small integers
  EXPECT_LT((vm.centroid - Vec3::Constant(0.5)).norm(), 1e-15);
  EXPECT_LT((vm.second_moment - Mat3::Identity() / 12.0).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_NEAR(surface_area(c), 6.0, 1e-14);
  EXPECT_LT((half_extents(c) - Vec3::Constant(0.5)).norm(), 1e-15);
}

TEST(InertiaEllipsoid, RotatedSpheroidAxesAndTranslationInvariance) {
  SurfaceMesh m = make_sphere_mesh(BaseSolid::Octahedron, 3);
  map_to_spheroid(m, 2.0, 0);  // long axis x1
  const InertiaEllipsoid e0 = inertia_ellipsoid(m);
  EXPECT_NEAR(e0.semi_axes[0] / e0.semi_axes[1], 2.0, 1e-12);  // affine image: exact ratio
  EXPECT_NEAR(e0.semi_axes[1], e0.semi_axes[2], 1e-12);
  // Rotate by 30° about x3 and translate: semi-axes unchanged, axis 1 follows the rotation.
  const double a = M_PI / 6;
  Mat3 R;
  R << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
  SurfaceMesh r = m;
  r.vertices = (m.vertices * R.transpose()).rowwise() + Eigen::RowVector3d(3, -2, 1);
  const InertiaEllipsoid e1 = inertia_ellipsoid(r);
  EXPECT_LT((e1.semi_axes - e0.semi_axes).norm(), 1e-12);
  EXPECT_NEAR(std::abs(e1.axes.col(0).dot(R.col(0))), 1.0, 1e-12);
  EXPECT_LT((e1.centroid - Vec3(3, -2, 1)).norm(), 1e-12);
}

TEST(NodalNormals, SphereNormalsAreRadial) {
  const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 4);
  const Points n = nodal_normals(m);
  double worst = 0;
  for (Eigen::Index i = 0; i < m.num_nodes(); ++i) worst = std::max(worst, (n.row(i) - m.vertices.row(i)).norm());
  EXPECT_LT(worst, 1e-2);  // area-weighted facet normals: O(h²) deviation, h ≈ 0.08 at level 4
}

// The centroid's rate along node velocities v: a rigid translation moves it by v exactly; any
// motion agrees with a central difference of volume_moments (error O(ε²) ≈ 1e-10 at ε = 1e-5,
// against rates of order 1).
TEST(CentroidRate, IsTheDerivativeOfTheVolumeCentroid) {
  SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 2);
  m.vertices.col(2) *= 1.4;                                    // a spheroid,
  m.vertices.rowwise() += Eigen::RowVector3d(0.3, -1.0, 2.0);  // away from the origin
  Points shift(m.vertices.rows(), 3);
  shift.rowwise() = Eigen::RowVector3d(0.5, -2.0, 1.0);
  EXPECT_LT((centroid_rate(m.vertices, m.triangles, shift) - Vec3(0.5, -2.0, 1.0)).norm(), 1e-13) << "a translation";
  // A deforming, rotating motion: v = A x + a smooth non-linear part.
  Points v(m.vertices.rows(), 3);
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    const Vec3 x = m.vertices.row(i).transpose();
    v.row(i) << 0.2 * x[1] - 0.7 * x[2] + std::sin(x[0]), x[0] * x[2] - 0.1, std::cos(2 * x[1]) + 0.3 * x[0] * x[0];
  }
  const double eps = 1e-5;
  const Vec3 fd = (volume_moments(m.vertices + eps * v, m.triangles).centroid -
                   volume_moments(m.vertices - eps * v, m.triangles).centroid) / (2 * eps);
  EXPECT_LT((centroid_rate(m.vertices, m.triangles, v) - fd).norm(), 1e-8);
}
