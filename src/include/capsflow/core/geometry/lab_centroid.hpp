#pragma once
// The capsule's centroid in the lab frame. The shape is computed in the frame of the centroid
// (rhs/capsule_dynamics.cpp: v∞ = L (x − c), docs/conventions.md §3.1), where the centroid c moves
// only by the disturbance flow's asymmetry; in the lab frame dC/dt = L C + ċ. Over a step of
// length τ in which c moves by Δc at a constant rate,
//   C(t + τ) = e^{Lτ} C(t) + φ1(Lτ) Δc,   φ1(z) = (e^z − 1)/z,
// exact for that motion: both terms are blocks of the exponential of the 4×4 matrix
// [[Lτ, Δc], [0, 0]], so a planar hyperbolic flow's e^{γ̇t} growth is carried by this 3-vector
// alone and never by the node positions.
#include "capsflow/core/types.hpp"

namespace capsflow {

Vec3 advance_lab_centroid(const Mat3& L, double tau, const Vec3& C, const Vec3& dc);

}  // namespace capsflow
