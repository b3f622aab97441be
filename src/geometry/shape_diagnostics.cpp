#include "capsflow/core/geometry/shape_diagnostics.hpp"


namespace capsflow {

ShapeDiagnostics shape_diagnostics(const SurfaceMesh& m) {
  ShapeDiagnostics d;
  const InertiaEllipsoid e = inertia_ellipsoid(m);
  d.D = taylor_deformation(e);
  d.Le = e.semi_axes;
  d.L = half_extents(m);
  d.area = surface_area(m);
  d.volume = enclosed_volume(m);
  return d;
}

}  // namespace capsflow
