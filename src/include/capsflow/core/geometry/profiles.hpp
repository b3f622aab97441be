#pragma once
// Cross-section profiles of the capsule surface with the coordinate planes through a point
// (by default the volume centroid): the paper's profile figures (x1x3 flow plane, x2x3 cross
// plane). Each section is a set of closed polylines of points on the P1 surface.
#include <vector>

#include "capsflow/core/types.hpp"

namespace capsflow {

enum class CoordinatePlane { X1X2, X1X3, X2X3 };  // normal along x3, x2, x1 respectively

const char* to_string(CoordinatePlane p);

struct Polyline {
  std::vector<Vec3> points;
  bool closed = false;
};

// Intersection of the surface with the plane {x : x_k = origin_k}, k the plane's normal axis.
// Vertices exactly on the plane are treated as lying on the positive side (a consistent
// symbolic perturbation), so every crossing edge contributes exactly one point.
std::vector<Polyline> cross_section(const SurfaceMesh& mesh, CoordinatePlane plane, const Vec3& origin);

}  // namespace capsflow
