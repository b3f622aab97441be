#include "capsflow/core/rhs/wall_factory.hpp"

#include <cmath>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/shell/gsmb_wall.hpp"

namespace capsflow {

shell::MembraneLaw scene_law(const Scene& s) {
  // Non-dimensional: μ = γ̇ = ℓ = 1, so G_s = 1/Ca_s (docs/conventions.md §1).
  // shell::make_law takes the law's one extra parameter in its last slot: C for Skalak, Ψ for Mooney–Rivlin.
  const double parameter = s.wall.law == shell::LawKind::MooneyRivlin ? s.wall.mooney_rivlin_psi : s.wall.skalak_c;
  return shell::make_law(s.wall.law, 1.0 / s.flow.ca_s, s.wall.poisson, parameter);
}

namespace {

// x ↦ c + scale · diag(axial, across, across) (x − c), c the volume centroid of `mesh`.
Points scaled_about_centroid(const SurfaceMesh& mesh, double scale, double axial, double across) {
  const Vec3 c = volume_moments(mesh).centroid;
  Points x = mesh.vertices;
  x.rowwise() -= c.transpose();
  x.col(0) *= scale * axial;
  x.col(1) *= scale * across;
  x.col(2) *= scale * across;
  x.rowwise() += c.transpose();
  return x;
}

}  // namespace

Points stress_free_nodes(const SurfaceMesh& initial, double prestress, double stretch) {
  if (prestress == 0 && stretch == 1) return initial.vertices;
  return scaled_about_centroid(initial, 1 / (1 + prestress), 1 / stretch, std::sqrt(stretch));
}

Points stretched_nodes(const SurfaceMesh& mesh, double stretch) {
  if (stretch == 1) return mesh.vertices;
  return scaled_about_centroid(mesh, 1, stretch, 1 / std::sqrt(stretch));
}

std::unique_ptr<shell::Wall> make_wall(const Scene& s, const SurfaceMesh& initial) {
  const shell::MembraneLaw law = scene_law(s);
  const Points X = stress_free_nodes(initial, s.wall.prestress, s.wall.initial_stretch);
  if (s.wall.model == WallModel::Membrane) return std::make_unique<shell::MembraneWall>(X, initial.triangles, law);
  shell::GsmbOptions opt;
  opt.thickness = s.wall.thickness;
  opt.poisson = s.wall.poisson;
  opt.max_newton = s.wall.max_newton;
  return std::make_unique<shell::GsmbWall>(X, initial.triangles, law, opt);
}

}  // namespace capsflow
