#include "capsflow/core/mesh/umbrella.hpp"

#include <algorithm>
#include <cstdint>

namespace capsflow {

UmbrellaOperator::UmbrellaOperator(const Triangles& triangles, Eigen::Index num_nodes) {
  std::vector<std::vector<int>> adj(static_cast<size_t>(num_nodes));
  for (Eigen::Index e = 0; e < triangles.rows(); ++e)
    for (int k = 0; k < 3; ++k) {
      const int a = triangles(e, k), b = triangles(e, (k + 1) % 3);
      adj[a].push_back(b);
      adj[b].push_back(a);
    }
  offsets_.assign(1, 0);
  for (auto& nb : adj) {
    std::sort(nb.begin(), nb.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    neighbours_.insert(neighbours_.end(), nb.begin(), nb.end());
    offsets_.push_back(static_cast<int>(neighbours_.size()));
  }
}

void UmbrellaOperator::apply(const Points& p, Points& out) const {
  const Eigen::Index n = num_nodes();
  out.resize(n, 3);
#pragma omp parallel for schedule(static)
  for (Eigen::Index i = 0; i < n; ++i) {
    Eigen::RowVector3d mean = Eigen::RowVector3d::Zero();
    for (int k = offsets_[i]; k < offsets_[i + 1]; ++k) mean += p.row(neighbours_[k]);
    const int deg = offsets_[i + 1] - offsets_[i];
    out.row(i) = deg > 0 ? Eigen::RowVector3d(mean / deg - p.row(i)) : Eigen::RowVector3d::Zero();
  }
}

Points grid_scale_pattern(const UmbrellaOperator& u, int sweeps) {
  const Eigen::Index n = u.num_nodes();
  Points p(n, 3), q;
  // A fixed linear congruential sequence: the same pattern on every machine and thread count.
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  for (Eigen::Index i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      p(i, c) = static_cast<double>(state >> 11) * 0x1.0p-53 - 0.5;
    }
  for (int s = 0; s < sweeps; ++s) {
    u.apply(p, q);
    std::swap(p, q);
    p /= p.norm();
  }
  if (sweeps == 0) p /= p.norm();
  return p;
}

}  // namespace capsflow
