#pragma once
// The umbrella operator of a triangulated surface: (U p)_i = mean of p over the neighbours of
// node i, minus p_i. It is a graph Laplacian: smooth fields give small values, and its
// largest-magnitude eigenvectors oscillate at the two-element wavelength — the same modes that set
// the stiffness of a discretised membrane or shell. Used by the grid-scale roughness monitor.
#include <vector>

#include "capsflow/core/types.hpp"

namespace capsflow {

class UmbrellaOperator {
 public:
  UmbrellaOperator() = default;
  explicit UmbrellaOperator(const Triangles& triangles, Eigen::Index num_nodes);

  Eigen::Index num_nodes() const { return static_cast<Eigen::Index>(offsets_.size()) - 1; }
  // out = U p (N × 3, any per-node vectors). out must not alias p.
  void apply(const Points& p, Points& out) const;
  // The same for a scalar per node.
  void apply(const Eigen::VectorXd& p, Eigen::VectorXd& out) const;
  // The neighbours of node i: neighbours()[offsets()[i] .. offsets()[i+1]).
  const std::vector<int>& offsets() const { return offsets_; }
  const std::vector<int>& neighbours() const { return neighbours_; }

 private:
  std::vector<int> offsets_{0}, neighbours_;
};

// A deterministic field dominated by the two-element-wavelength modes: a fixed pseudo-random
// field passed `sweeps` times through U (each pass multiplies a mode by its eigenvalue in [−2, 0],
// so smooth modes die out), normalised to unit Frobenius norm.
Points grid_scale_pattern(const UmbrellaOperator& u, int sweeps = 8);

}  // namespace capsflow
