#pragma once
// Capsule meshes: subdivided icosahedron (20·4^k triangles) or octahedron (8·4^k), vertices
// projected on the unit sphere after every subdivision (as in the paper, §4.1), optionally mapped
// affinely to a prolate/oblate spheroid. Vertices are shared, triangles oriented outward (CCW seen
// from outside). Both bases are centrally symmetric, which makes the volume-based Taylor
// deformation of the spheroid exact (docs/conventions.md §5.2).
#include <string>

#include "capsflow/core/named_enum.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

enum class BaseSolid { Icosahedron, Octahedron };

inline constexpr NameTable<BaseSolid, 2> kBaseSolidNames{
    {{BaseSolid::Icosahedron, "icosahedron"}, {BaseSolid::Octahedron, "octahedron"}}};
constexpr const auto& name_table(BaseSolid) { return kBaseSolidNames; }

// The base solid subdivided `level` times, every vertex projected on the unit sphere.
SurfaceMesh make_sphere_mesh(BaseSolid base, int level);

// Affine map of a unit-sphere mesh to the spheroid with semi-axis a along `axis` (0, 1 or 2) and
// b on the two others, aspect = a/b, then a uniform scale so that the *discrete* enclosed volume
// gives ℓ = (3V/4π)^(1/3) = 1 exactly (docs/conventions.md §4.2). aspect = 1 gives the volume-scaled sphere.
void map_to_spheroid(SurfaceMesh& mesh, double aspect, int axis);

// Uniform scale about the origin so that the discrete volume gives ℓ = 1.
void scale_to_unit_equivalent_radius(SurfaceMesh& mesh);

// Expected counts for a subdivided base solid: elements, nodes, edges.
struct MeshCounts {
  long elements, nodes, edges;
};
MeshCounts expected_counts(BaseSolid base, int level);

}  // namespace capsflow
