// Validation of user meshes: each failure class gives its own error naming the first culprit.
#include <gtest/gtest.h>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/mesh/topology.hpp"

using namespace capsflow;

namespace {
std::string error_of(SurfaceMesh m) {
  try {
    validate_closed_surface(m);
  } catch (const MeshError& e) {
    return e.what();
  }
  return "";
}
SurfaceMesh octa() { return make_sphere_mesh(BaseSolid::Octahedron, 0); }
}  // namespace

TEST(MeshTopology, AcceptsGeneratedMeshes) {
  EXPECT_EQ(error_of(octa()), "");
  EXPECT_EQ(error_of(make_sphere_mesh(BaseSolid::Icosahedron, 2)), "");
}

TEST(MeshTopology, OpenSurfaceNamesBoundaryEdge) {
  SurfaceMesh m = octa();
  SurfaceMesh open;
  open.vertices = m.vertices;
  open.triangles = m.triangles.topRows(7);  // drop one face
  const std::string e = error_of(open);
  EXPECT_NE(e.find("not closed"), std::string::npos) << e;
  EXPECT_NE(e.find("boundary edge"), std::string::npos) << e;
}

TEST(MeshTopology, FlippedFaceIsInconsistentOrientation) {
  SurfaceMesh m = octa();
  std::swap(m.triangles(3, 1), m.triangles(3, 2));
  const std::string e = error_of(m);
  EXPECT_NE(e.find("inconsistent orientation"), std::string::npos) << e;
  EXPECT_NE(e.find("element 3"), std::string::npos) << e;  // names the flipped element
}

TEST(MeshTopology, NonManifoldEdge) {
  SurfaceMesh a = octa();
  SurfaceMesh m;
  m.vertices.resize(8, 3);
  m.vertices.topRows(6) = a.vertices;
  // Two extra faces on edge (0, 4) make it shared by four faces.
  m.vertices.row(6) << 2, 0.5, 0.5;
  m.vertices.row(7) << 2, -0.5, 0.5;
  m.triangles.resize(10, 3);
  m.triangles.topRows(8) = a.triangles;
  m.triangles.row(8) << 0, 4, 6;
  m.triangles.row(9) << 4, 0, 7;
  const std::string e = error_of(m);
  EXPECT_NE(e.find("non-manifold edge"), std::string::npos) << e;
}

TEST(MeshTopology, NonManifoldVertex) {
  // Two octahedra touching at a single vertex: closed, edge-manifold, but the shared vertex has
  // two separate fans.
  SurfaceMesh a = octa();
  SurfaceMesh m;
  m.vertices.resize(11, 3);
  m.vertices.topRows(6) = a.vertices;
  m.triangles.resize(16, 3);
  m.triangles.topRows(8) = a.triangles;
  // Second octahedron centred at (2,0,0); its vertex (−1,0,0)+(2,0,0) = (1,0,0) is vertex 0.
  std::array<int, 6> map{5 + 1, 0, 5 + 2, 5 + 3, 5 + 4, 5 + 5};
  for (int i = 0; i < 6; ++i)
    if (map[i] != 0) m.vertices.row(map[i]) = a.vertices.row(i) + Eigen::RowVector3d(2, 0, 0);
  for (int t = 0; t < 8; ++t)
    for (int k = 0; k < 3; ++k) m.triangles(8 + t, k) = map[a.triangles(t, k)];
  const std::string e = error_of(m);
  EXPECT_NE(e.find("non-manifold vertex 0"), std::string::npos) << e;
}

TEST(MeshTopology, DegenerateRepeatedVertex) {
  SurfaceMesh m = octa();
  m.triangles(2, 1) = m.triangles(2, 0);
  EXPECT_NE(error_of(m).find("element 2"), std::string::npos);
}

TEST(MeshTopology, ZeroAreaElement) {
  // Move the apex of a valid closed mesh onto the plane of one face: that face keeps its area, but
  // collapsing vertex 4 onto vertex 0 gives zero-area faces.
  SurfaceMesh m = octa();
  m.vertices.row(4) = m.vertices.row(0);
  EXPECT_NE(error_of(m).find("zero area"), std::string::npos) << error_of(m);
}

TEST(MeshTopology, IndexOutOfRangeAndNaN) {
  SurfaceMesh m = octa();
  m.triangles(5, 2) = 99;
  EXPECT_NE(error_of(m).find("out of range"), std::string::npos);
  SurfaceMesh n = octa();
  n.vertices(3, 1) = std::nan("");
  EXPECT_NE(error_of(n).find("vertex 3 has a non-finite"), std::string::npos);
}

TEST(MeshTopology, UnusedVertexAndTwoComponents) {
  SurfaceMesh m = octa();
  m.vertices.conservativeResize(7, 3);
  m.vertices.row(6) << 5, 5, 5;
  EXPECT_NE(error_of(m).find("vertex 6 is not used"), std::string::npos);

  SurfaceMesh a = octa(), two;
  two.vertices.resize(12, 3);
  two.vertices << a.vertices, a.vertices.rowwise() + Eigen::RowVector3d(5, 0, 0);
  two.triangles.resize(16, 3);
  two.triangles << a.triangles, a.triangles.array() + 6;
  EXPECT_NE(error_of(two).find("more than one connected component"), std::string::npos) << error_of(two);
}

TEST(MeshTopology, InwardMeshIsFlipped) {
  SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, 1);
  m.triangles.col(1).swap(m.triangles.col(2));
  ASSERT_LT(enclosed_volume(m), 0);
  EXPECT_TRUE(validate_closed_surface(m));  // consistently inward: flipped, reported
  EXPECT_GT(enclosed_volume(m), 0);
}

TEST(MeshTopology, PinchedSurfaceIsRejected) {
  // Every topological check passes when one vertex is moved onto another, non-adjacent one: the
  // surface then touches itself at a point. Vertex 0 and the vertex farthest from it are not
  // neighbours on the level-2 icosphere.
  const SurfaceMesh sphere = make_sphere_mesh(BaseSolid::Icosahedron, 2);
  Eigen::Index far = 0;
  (sphere.vertices.rowwise() - sphere.vertices.row(0)).rowwise().norm().maxCoeff(&far);
  SurfaceMesh m = sphere;
  m.vertices.row(far) = m.vertices.row(0);
  const std::string e = error_of(m);
  EXPECT_NE(e.find("vertices 0 and " + std::to_string(far) + " are at the same position"), std::string::npos) << e;
  EXPECT_NE(e.find("pinched"), std::string::npos) << e;
  EXPECT_EQ(e.find("merge duplicate"), std::string::npos) << e;  // one pair is a pinch, not a soup
  // Nearly touching counts too: 1e-9 of the radius is far inside the 1e-6·(mean edge) tolerance.
  SurfaceMesh n = sphere;
  n.vertices.row(far) = n.vertices.row(0) * (1 + 1e-9);
  EXPECT_NE(error_of(n).find("pinched"), std::string::npos) << error_of(n);
}

TEST(MeshTopology, TriangleSoupSuggestsMergingDuplicateVertices) {
  // Each triangle with its own three vertices (STL converted to OFF): nothing is connected.
  const SurfaceMesh m = octa();
  SurfaceMesh soup;
  soup.vertices.resize(3 * m.num_elements(), 3);
  soup.triangles.resize(m.num_elements(), 3);
  for (Eigen::Index e = 0; e < m.num_elements(); ++e)
    for (int k = 0; k < 3; ++k) {
      soup.vertices.row(3 * e + k) = m.vertices.row(m.triangles(e, k));
      soup.triangles(e, k) = static_cast<int>(3 * e + k);
    }
  const std::string e = error_of(soup);
  EXPECT_NE(e.find("not closed"), std::string::npos) << e;
  EXPECT_NE(e.find("24 of the 24 vertices share their position"), std::string::npos) << e;
  EXPECT_NE(e.find("merge duplicate vertices"), std::string::npos) << e;
  // An ordinary open surface gets no such hint.
  SurfaceMesh open{m.vertices, m.triangles.topRows(7)};
  EXPECT_EQ(error_of(open).find("merge"), std::string::npos) << error_of(open);
}

// A mesh in absurd units: areas of a sphere scaled by 1e300 overflow to inf and by 1e-300 underflow
// to 0, which used to be reported as "zero area (degenerate)" on a perfectly shaped mesh.
TEST(MeshTopology, CoordinatesOutsideTheRepresentableScaleAreNamedAsSuch) {
  for (double scale : {1e300, 1e-300}) {
    SurfaceMesh m = octa();
    m.vertices *= scale;
    const std::string err = error_of(m);
    EXPECT_NE(err.find("rescale the mesh"), std::string::npos) << scale << ": " << err;
    EXPECT_EQ(err.find("zero area"), std::string::npos) << err;
  }
  SurfaceMesh fine = octa();
  fine.vertices *= 1e-6;  // micrometres: a legitimate unit, accepted
  EXPECT_EQ(error_of(fine), "");
}
