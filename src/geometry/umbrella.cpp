#include "capsflow/core/geometry/umbrella.hpp"

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

namespace {
// (U p)_i for any per-node rows (N × 3 vectors or N scalars).
template <class M>
void apply_umbrella(const std::vector<int>& off, const std::vector<int>& nb, const M& p, M& out) {
  const Eigen::Index n = static_cast<Eigen::Index>(off.size()) - 1;
  out.resize(n, p.cols());
#pragma omp parallel for schedule(static)
  for (Eigen::Index i = 0; i < n; ++i) {
    const int deg = off[i + 1] - off[i];
    if (deg == 0) {
      out.row(i).setZero();
      continue;
    }
    out.row(i).setZero();
    for (int k = off[i]; k < off[i + 1]; ++k) out.row(i) += p.row(nb[k]);
    out.row(i) = out.row(i) / deg - p.row(i);  // the neighbours' mean minus the value
  }
}
}  // namespace

void UmbrellaOperator::apply(const Points& p, Points& out) const { apply_umbrella(offsets_, neighbours_, p, out); }
void UmbrellaOperator::apply(const Eigen::VectorXd& p, Eigen::VectorXd& out) const {
  apply_umbrella(offsets_, neighbours_, p, out);
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
