#pragma once
// The double layer of a constant at a vertex of a closed polyhedron, in closed form
// (docs/boundary-integral.md §4.7.5):
//
//   D[1](x) = (1/8π) PV∫_S T(x − y)·n(y) dS_y = (3/4π) M,   M = ∫_{Ω_in} d dᵀ dΩ,
//
// Ω_in the directions d pointing from x into the polyhedron (its inner tangent cone: a half
// sphere at a smooth point, where M = (2π/3) I and D[1] = ½ I). T is divergence-free away from
// x, so the integral over S equals the flux through a small sphere about x: only the cone at x
// counts. M splits into its trace, the cone's solid angle, and a degree-2 harmonic whose
// integral over a spherical polygon is a sum over its great-circle arcs:
//
//   M = (Ω_in/3) I − (1/6) Σ_f tan(θ_f/2) (n_f (a_f + b_f)ᵀ + (a_f + b_f) n_f ᵀ),
//   Ω_in = 2π − Σ_edges ψ_e,
//
// per facet f = (x, p, q): a, b the unit directions to p and q, θ_f their angle, n_f the outward
// unit normal; per edge e of the vertex, ψ_e the signed angle between the normals of its two
// facets (positive where the edge is convex). Every term is local: the whole surface's integral
// from the vertex's facets alone.
#include <vector>

#include "capsflow/core/types.hpp"

namespace capsflow {

// One facet of the vertex's fan: the other two vertices, counter-clockwise seen from outside
// (outward normal (p − x) × (q − x)), and the fan position of the facet whose p is this q.
struct CornerFacet {
  int p, q, next;
};

// The fans of every node of a closed triangulation (facets (i, p, q) of each element touching i,
// rotated to start at i), in CSR form. Throws std::invalid_argument if a fan is not closed.
struct CornerFans {
  std::vector<int> start;          // fan of node i: facets[start[i] .. start[i+1])
  std::vector<CornerFacet> facets;  // next is relative to start[i]
  explicit CornerFans(const Triangles& triangles, Eigen::Index n_nodes);
};

// D[1](x_i) for node i of the closed polyhedron with nodes x (symmetric 3×3).
Mat3 corner_double_layer(const Points& x, Eigen::Index i, const CornerFans& fans);

}  // namespace capsflow
