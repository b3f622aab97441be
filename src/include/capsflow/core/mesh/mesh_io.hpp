#pragma once
// Reading and writing closed surface meshes so users can bring their own: OFF (ASCII) and PLY
// (ASCII or binary little-endian; vertex x y z + face vertex_indices). Every mesh read is checked
// with validate_closed_surface(); parse errors name the file and line (ASCII) or element.
#include <string>

#include "capsflow/core/mesh/topology.hpp"

namespace capsflow {

// Reads by extension (.off, .ply), validates, and orients outward. Throws MeshError.
SurfaceMesh read_mesh(const std::string& path);
SurfaceMesh read_off(const std::string& path);
SurfaceMesh read_ply(const std::string& path);

// Writes by extension (.off, .ply as ASCII), full double precision.
void write_mesh(const SurfaceMesh& mesh, const std::string& path);

}  // namespace capsflow
