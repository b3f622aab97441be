#include "capsflow/core/rhs/wall_factory.hpp"

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/shell/gsmb_wall.hpp"

namespace capsflow {

shell::MembraneLaw scene_law(const Scene& s) {
  // Non-dimensional: μ = γ̇ = ℓ = 1, so G_s = 1/Ca_s (docs/conventions.md §1).
  // shell::make_law takes the law's one extra parameter in its last slot: C for Skalak, Ψ for Mooney–Rivlin.
  const double parameter = s.wall.law == shell::LawKind::MooneyRivlin ? s.wall.mooney_rivlin_psi : s.wall.skalak_c;
  return shell::make_law(s.wall.law, 1.0 / s.flow.ca_s, s.wall.poisson, parameter);
}

Points stress_free_nodes(const SurfaceMesh& initial, double prestress) {
  if (prestress == 0) return initial.vertices;
  const Vec3 c = volume_moments(initial).centroid;
  Points x = initial.vertices;
  x.rowwise() -= c.transpose();
  x /= 1 + prestress;
  x.rowwise() += c.transpose();
  return x;
}

std::unique_ptr<shell::Wall> make_wall(const Scene& s, const SurfaceMesh& initial) {
  const shell::MembraneLaw law = scene_law(s);
  const Points X = stress_free_nodes(initial, s.wall.prestress);
  if (s.wall.model == WallModel::Membrane) return std::make_unique<shell::MembraneWall>(X, initial.triangles, law);
  shell::GsmbOptions opt;
  opt.thickness = s.wall.thickness;
  opt.poisson = s.wall.poisson;
  opt.max_newton = s.wall.max_newton;
  return std::make_unique<shell::GsmbWall>(X, initial.triangles, law, opt);
}

}  // namespace capsflow
