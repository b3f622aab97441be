// A pre-inflated wall (wall.prestress = α_p): a sphere of radius R whose stress-free shape is the
// sphere of radius R/(1 + α_p) carries the isotropic tension T of the stretch λ = 1 + α_p in
// every direction, so its load is Laplace's, q = (2T/R) n (outward: the stretched wall pulls
// inward on the fluid inside, rhs/wall_factory.hpp and shell/wall.hpp's sign), and in a quiescent
// fluid nothing moves: a uniform normal load on a closed surface is a pressure.
#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/driver/capsule_placement.hpp"
#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/rhs/capsule_dynamics.hpp"
#include "capsflow/core/rhs/wall_factory.hpp"

using namespace capsflow;

namespace {

struct LaplaceLoad {
  double normal_mean = 0;       // area-weighted mean of q·n
  double normal_rms = 0;        // area-weighted RMS of q·n − mean
  double tangential_max = 0;    // largest |q − (q·n) n|
};

// The load of the scene's wall at its initial (inflated) nodes, the sphere moved off the origin so
// that shrinking about the origin instead of the centroid would show as a non-uniform load.
LaplaceLoad load_of(const std::vector<std::string>& overrides, const Vec3& shift) {
  std::vector<std::string> all = {"mesh.level=4", "mesh.shape=\"sphere\"", "flow.type=\"quiescent\"", "flow.ca_s=1"};
  all.insert(all.end(), overrides.begin(), overrides.end());
  const Scene s = parse_scene(default_scene_toml(), "test", all);
  SurfaceMesh m = make_reference_mesh(s.mesh);
  m.vertices.rowwise() += shift.transpose();
  CapsuleDynamics dyn(s, m);
  Points v;
  dyn.velocity(m.vertices, v);
  const Points& q = dyn.load();
  const Points n = nodal_normals(m);
  const Eigen::VectorXd a = nodal_areas(m);
  LaplaceLoad out;
  Eigen::VectorXd qn(q.rows());
  for (Eigen::Index i = 0; i < q.rows(); ++i) {
    qn[i] = q.row(i).dot(n.row(i));
    out.tangential_max = std::max(out.tangential_max, (q.row(i) - qn[i] * n.row(i)).norm());
  }
  out.normal_mean = a.dot(qn) / a.sum();
  out.normal_rms = std::sqrt(a.dot((qn.array() - out.normal_mean).square().matrix()) / a.sum());
  return out;
}

// Closed-form principal tensions at λ1 = λ2 = λ (docs/shell.md §2.3), G_s = 1.
double skalak_tension(double l, double C) { return (l * l - 1) * (1 + C * l * l * (l * l + 1)); }
double neo_hookean_tension(double l) { return (l * l - std::pow(l, -4)) / (l * l); }
double hooke_tension(double l, double nu) { return (1 + nu) * (l * l - 1) / (1 - nu); }

}  // namespace

TEST(Prestress, StressFreeNodesAreTheInitialOnesShrunkAboutTheCentroid) {
  SurfaceMesh m = make_reference_mesh(MeshSpec());
  m.vertices.rowwise() += Vec3(0.3, -2, 5).transpose();
  const Points X = stress_free_nodes(m, 0.1);
  const Vec3 c = volume_moments(m).centroid;
  const Vec3 C = volume_moments(X, m.triangles).centroid;
  EXPECT_LT((C - c).norm(), 1e-12);  // round-off of a shrink about c, which stays put
  EXPECT_NEAR(enclosed_volume(SurfaceMesh{X, m.triangles}), enclosed_volume(m) / std::pow(1.1, 3), 1e-12);  // exact scaling
  EXPECT_EQ(stress_free_nodes(m, 0), m.vertices);  // exact: no prestress, no arithmetic
}

TEST(Prestress, PreInflatedMembraneSphereCarriesLaplacesLoad) {
  // 2 562 nodes: the mean normal load is the smooth one's to O(h²) (0.07 % measured), so 0.5 %;
  // node by node it varies by 2 % RMS (the icosphere's irregular nodes), so 5 %; the tangential
  // part is 1.2 % of it at most, so 2 %. A wrong stretch — (1 + α_p)², or about the origin — fails by far.
  const double alpha = 0.05, l = 1 + alpha;
  const Vec3 shift(0.7, -0.4, 1.3);
  struct Case {
    const char* law;
    std::vector<std::string> keys;
    double tension;
  };
  for (const Case& c : {Case{"skalak", {"wall.law=\"skalak\"", "wall.skalak_c=1"}, skalak_tension(l, 1)},
                        Case{"nh", {"wall.law=\"nh\""}, neo_hookean_tension(l)},
                        Case{"gh", {"wall.law=\"gh\"", "wall.poisson=0.5"}, hooke_tension(l, 0.5)}}) {
    std::vector<std::string> keys = c.keys;
    keys.insert(keys.end(), {"wall.model=\"membrane\"", "wall.prestress=0.05"});
    const LaplaceLoad q = load_of(keys, shift);
    EXPECT_NEAR(q.normal_mean, 2 * c.tension, 0.005 * 2 * c.tension) << c.law;
    EXPECT_LT(q.normal_rms, 0.05 * 2 * c.tension) << c.law;  // uniform but for the icosphere's irregular nodes
    EXPECT_LT(q.tangential_max, 0.02 * 2 * c.tension) << c.law;   // and normal
  }
}

TEST(Prestress, PreInflatedShellSphereCarriesLaplacesLoadPlusItsBendingShare) {
  // GSMB, h = 0.03: a uniform inflation also changes the curvature, by which a linear bending
  // term adds O(B/(G_s R²)) = O(h²) ≈ 1e-3 of the membrane load: 2 % as for the membrane.
  const double l = 1.05;
  const LaplaceLoad q = load_of({"wall.model=\"gsmb\"", "wall.law=\"skalak\"", "wall.skalak_c=1", "wall.prestress=0.05"},
                                Vec3(0.7, -0.4, 1.3));
  EXPECT_NEAR(q.normal_mean, 2 * skalak_tension(l, 1), 0.02 * 2 * skalak_tension(l, 1));
  EXPECT_LT(q.tangential_max, 0.02 * 2 * skalak_tension(l, 1));
}

TEST(Prestress, PreInflatedSphereInQuiescentFluidDoesNotMove) {
  // Laplace's load is a pressure jump: −S[q] vanishes on the closed sphere. Discretely it is the
  // single layer of a nearly uniform normal load, O(h²) of q R ≈ 0.7 at 642 nodes; a load shrunk
  // about the wrong point, or not normal, moves the sphere at O(q R).
  const Scene s = parse_scene(default_scene_toml(), "test",
                              {"mesh.level=3", "mesh.shape=\"sphere\"", "flow.type=\"quiescent\"", "flow.ca_s=1",
                               "wall.model=\"membrane\"", "wall.law=\"skalak\"", "wall.prestress=0.05"});
  SurfaceMesh m = make_reference_mesh(s.mesh);
  m.vertices.rowwise() += Vec3(2, 0, -1).transpose();
  CapsuleDynamics dyn(s, m);
  Points v;
  dyn.velocity(m.vertices, v);
  const double qR = dyn.load().rowwise().norm().maxCoeff();
  EXPECT_GT(qR, 0.5);  // the wall is loaded (2T/R = 0.68 for Skalak C = 1 at λ = 1.05)
  EXPECT_LT(v.rowwise().norm().maxCoeff(), 0.01 * qR);
}

TEST(Prestress, AStretchedStartKeepsTheVolumeAndTheMeshAsTheStressFreeShape) {
  // wall.initial_stretch = 1.3: the sphere starts as the spheroid of semi-axes 1.3 and 1/√1.3 (the
  // same volume), and its wall is stress-free at the mesh's sphere shrunk by 1 + α_p.
  const Scene s = parse_scene(default_scene_toml(), "test",
                              {"mesh.level=3", "mesh.shape=\"sphere\"", "flow.type=\"quiescent\"", "flow.ca_s=1",
                               "wall.model=\"membrane\"", "wall.law=\"nh\"", "wall.initial_stretch=1.3",
                               "wall.prestress=0.05"});
  const SurfaceMesh sphere = make_reference_mesh(s.mesh);
  const SurfaceMesh start = place_capsules(s).mesh();
  const double r = sphere.vertices.col(0).maxCoeff();  // the mesh's nodes lie on a sphere of radius r ≈ 1
  EXPECT_NEAR(start.vertices.col(0).maxCoeff(), 1.3 * r, 1e-12);  // round-off of a scaling
  EXPECT_NEAR(start.vertices.col(1).maxCoeff(), r / std::sqrt(1.3), 1e-12);
  EXPECT_NEAR(enclosed_volume(start), enclosed_volume(sphere), 1e-12);  // a volume-keeping map
  const std::unique_ptr<shell::Wall> wall = make_wall(s, start);
  const Points stress_free = sphere.vertices / 1.05;
  EXPECT_LT(wall->energies(stress_free).total(), 1e-14);  // round-off of a zero strain (the stretched start's is ~1)
  EXPECT_GT(wall->energies(start.vertices).total(), 0.1);  // the stretched start stores energy (≈ G_s·area·strain²)
  EXPECT_LT((stress_free_nodes(start, 0.05, 1.3) - stress_free).cwiseAbs().maxCoeff(), 1e-14);  // the inverse map
}
