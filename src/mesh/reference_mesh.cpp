#include "capsflow/core/mesh/reference_mesh.hpp"

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/mesh/biconcave.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/mesh/mesh_io.hpp"

namespace capsflow {

SurfaceMesh make_reference_mesh(const MeshSpec& spec) {
  if (!spec.file.empty()) {
    SurfaceMesh m = read_mesh(spec.file);
    const Vec3 c = volume_moments(m).centroid;
    m.vertices.rowwise() -= c.transpose();
    scale_to_unit_equivalent_radius(m);
    return m;
  }
  SurfaceMesh m = make_sphere_mesh(spec.base, spec.level);
  if (spec.shape == MeshShape::Biconcave) {
    map_to_biconcave(m, 1.0, spec.axis - 1);
    scale_to_unit_equivalent_radius(m);
    return m;
  }
  map_to_spheroid(m, spec.shape == MeshShape::Sphere ? 1.0 : spec.aspect, spec.axis - 1);
  return m;
}

}  // namespace capsflow
