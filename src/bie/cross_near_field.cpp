#include "capsflow/core/bie/cross_near_field.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "capsflow/core/bie/point_triangle.hpp"
#include "capsflow/core/bie/quadrature.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow {

namespace {

constexpr double kInv8Pi = fmm::Stokeslet::scale();

struct Box {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -Vec3::Constant(std::numeric_limits<double>::infinity());
  void add(const Vec3& p) { lo = lo.cwiseMin(p), hi = hi.cwiseMax(p); }
  bool contains(const Vec3& p, double margin) const {
    return (p.array() >= lo.array() - margin).all() && (p.array() <= hi.array() + margin).all();
  }
  bool overlaps(const Box& o, double margin) const {
    return (lo.array() - margin <= o.hi.array()).all() && (o.lo.array() <= hi.array() + margin).all();
  }
};

Vec3 node(const Points& x, Eigen::Index i) { return x.row(i).transpose(); }

double longest_edge(const Points& x, const Triangles& tri, Eigen::Index e) {
  double h = 0;
  for (int k = 0; k < 3; ++k) h = std::max(h, (x.row(tri(e, k)) - x.row(tri(e, (k + 1) % 3))).norm());
  return h;
}

// One surface's elements by the cell of their centroid. A point within r element sizes of an
// element lies within (r + 1) sizes of its centroid (the centroid is within the longest edge of
// every point of the triangle): with cells of (r + 1) × the longest edge, every such element has
// its centroid in one of the 27 cells around the point's, and each element is in one cell only.
class CentroidCells {
 public:
  CentroidCells(const Points& x, const Triangles& tri, const SurfacePart& part, double cell) : cell_(cell) {
    Box box;
    std::vector<Vec3> c(static_cast<std::size_t>(part.elements));
    for (Eigen::Index k = 0; k < part.elements; ++k) {
      const Eigen::Index e = part.element_begin + k;
      c[static_cast<std::size_t>(k)] = (node(x, tri(e, 0)) + node(x, tri(e, 1)) + node(x, tri(e, 2))) / 3.0;
      box.add(c[static_cast<std::size_t>(k)]);
    }
    lo_ = box.lo;
    for (int d = 0; d < 3; ++d) n_[d] = static_cast<long>(std::floor((box.hi[d] - lo_[d]) / cell_)) + 1;
    sorted_.reserve(c.size());
    for (Eigen::Index k = 0; k < part.elements; ++k)
      sorted_.emplace_back(key(cell_of(c[static_cast<std::size_t>(k)])), static_cast<int>(part.element_begin + k));
    std::sort(sorted_.begin(), sorted_.end());
  }

  // The elements whose centroid lies in the 27 cells around p's (each once), into `out`, ascending.
  void candidates(const Vec3& p, std::vector<int>& out) const {
    out.clear();
    const std::array<long, 3> c = cell_of(p);
    for (long i = c[0] - 1; i <= c[0] + 1; ++i)
      for (long j = c[1] - 1; j <= c[1] + 1; ++j)
        for (long k = c[2] - 1; k <= c[2] + 1; ++k) {
          if (i < 0 || j < 0 || k < 0 || i >= n_[0] || j >= n_[1] || k >= n_[2]) continue;
          const long kk = key({i, j, k});
          auto it = std::lower_bound(sorted_.begin(), sorted_.end(), std::make_pair(kk, -1));
          for (; it != sorted_.end() && it->first == kk; ++it) out.push_back(it->second);
        }
    std::sort(out.begin(), out.end());
  }

 private:
  std::array<long, 3> cell_of(const Vec3& p) const {
    std::array<long, 3> c;
    for (int d = 0; d < 3; ++d) c[static_cast<std::size_t>(d)] = static_cast<long>(std::floor((p[d] - lo_[d]) / cell_));
    return c;
  }
  long key(const std::array<long, 3>& c) const { return (c[0] * n_[1] + c[1]) * n_[2] + c[2]; }

  Vec3 lo_;
  double cell_;
  long n_[3];
  std::vector<std::pair<long, int>> sorted_;  // (cell key, element)
};

}  // namespace

CrossNearField::CrossNearField(const SurfaceSet& set, double near_ratio, int threads)
    : tri_(set.mesh().triangles), near_ratio_(near_ratio), threads_(threads > 0 ? threads : omp_get_max_threads()) {
  if (!(near_ratio >= 0)) throw std::invalid_argument("cross-surface near field: near_ratio must be >= 0");
  for (int k = 0; k < set.size(); ++k) parts_.push_back(set.part(k));
}

void CrossNearField::find_pairs(const Points& x) {
  closest_ = SurfaceGap{};
  inside_nodes_ = 0;
  deepest_inside_ = SurfaceGap{};
  nearest_.clear();
  pair_node_.clear();
  pair_begin_.assign(1, 0);
  pair_element_.clear();
  const int K = static_cast<int>(parts_.size());
  if (K < 2 || near_ratio_ == 0) return;
  std::vector<Box> box(static_cast<std::size_t>(K));
  std::vector<double> hmax(static_cast<std::size_t>(K), 0.0);
  element_size_.resize(static_cast<std::size_t>(tri_.rows()));
  for (int k = 0; k < K; ++k) {
    const SurfacePart& p = parts_[static_cast<std::size_t>(k)];
    for (Eigen::Index i = p.node_begin; i < p.node_begin + p.nodes; ++i) box[static_cast<std::size_t>(k)].add(node(x, i));
    for (Eigen::Index e = p.element_begin; e < p.element_begin + p.elements; ++e) {
      element_size_[static_cast<std::size_t>(e)] = longest_edge(x, tri_, e);
      hmax[static_cast<std::size_t>(k)] = std::max(hmax[static_cast<std::size_t>(k)], element_size_[static_cast<std::size_t>(e)]);
    }
  }
  std::vector<std::pair<Eigen::Index, int>>& found = found_;
  std::vector<int>& cand = candidates_;
  found.clear();
  for (int k = 0; k < K; ++k) {
    const double reach = near_ratio_ * hmax[static_cast<std::size_t>(k)];
    std::optional<CentroidCells> cells;  // built when a surface comes near k
    for (int j = 0; j < K; ++j) {
      if (j == k || !box[static_cast<std::size_t>(j)].overlaps(box[static_cast<std::size_t>(k)], reach)) continue;
      if (!cells) cells.emplace(x, tri_, parts_[static_cast<std::size_t>(k)], (near_ratio_ + 1) * hmax[static_cast<std::size_t>(k)]);
      const SurfacePart& pj = parts_[static_cast<std::size_t>(j)];
      for (Eigen::Index i = pj.node_begin; i < pj.node_begin + pj.nodes; ++i) {
        const Vec3 p = node(x, i);
        if (!box[static_cast<std::size_t>(k)].contains(p, reach)) continue;
        cells->candidates(p, cand);
        SurfaceGap nearest;  // of node i to surface k
        for (int e : cand) {
          const Vec3 a = node(x, tri_(e, 0)), b = node(x, tri_(e, 1)), c = node(x, tri_(e, 2));
          const double h = element_size_[static_cast<std::size_t>(e)];
          const Vec3 foot = closest_point_on_triangle(p, a, b, c);
          const double d = (p - foot).norm();
          if (!(d < near_ratio_ * h)) continue;
          found.emplace_back(i, e);
          if (d < nearest.distance) nearest = {d / h, d, j, k, i, e, d == 0 || (p - foot).dot((b - a).cross(c - a)) < 0};
        }
        if (nearest.node >= 0) nearest_.push_back(nearest);
        if (nearest.inside) {
          ++inside_nodes_;
          if (deepest_inside_.node < 0 || nearest.distance > deepest_inside_.distance) deepest_inside_ = nearest;
        }
        if (nearest.ratio < closest_.ratio) closest_ = nearest;
      }
    }
  }
  std::sort(found.begin(), found.end());
  for (std::size_t f = 0; f < found.size(); ++f) {
    if (f == 0 || found[f].first != found[f - 1].first) {
      if (f > 0) pair_begin_.push_back(f);
      pair_node_.push_back(found[f].first);
    }
    pair_element_.push_back(found[f].second);
  }
  if (!found.empty()) pair_begin_.push_back(found.size());
}

void CrossNearField::correct(const Points& x, const Points& q, const SingleLayer& S, Points& u) const {
  const BoundarySurface& surface = S.surface();
  const long n = static_cast<long>(pair_node_.size());
#pragma omp parallel for schedule(dynamic, 8) num_threads(threads_)
  for (long k = 0; k < n; ++k) {
    const Eigen::Index i = pair_node_[static_cast<std::size_t>(k)];
    const Vec3 p = node(x, i);
    Vec3 sum = Vec3::Zero();
    for (std::size_t f = pair_begin_[static_cast<std::size_t>(k)]; f < pair_begin_[static_cast<std::size_t>(k) + 1]; ++f) {
      const int e = pair_element_[f];
      sum += adaptive_element_apply(p, surface.element(x, e, 0), q.row(tri_(e, 0)).transpose(),
                                    q.row(tri_(e, 1)).transpose(), q.row(tri_(e, 2)).transpose()) -
             S.element_far_terms(e, p);
    }
    u.row(i) += kInv8Pi * sum.transpose();
  }
}

}  // namespace capsflow
