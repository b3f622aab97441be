#pragma once
// Near-singular integration between surfaces (docs/boundary-integral.md §4.9). The far field sees
// an element through its rule points, accurate for targets farther than about two element sizes;
// a node of one surface closer than near_ratio sizes to an element of another gets that element's
// far-field terms replaced by the adaptive integral (quadrature.hpp), the way the self near field
// replaces them on a surface's own elements. The search also finds the smallest gap.
#include <limits>
#include <utility>
#include <vector>

#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/geometry/surface_set.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

// Corrected within 3 element sizes: where the self near field stops (its band: 3 rings of
// elements), so that a node sees another surface with the same accuracy as its own.
inline constexpr double kCrossNearRatio = 3.0;

// The closest (node, element of another surface) pair within near_ratio element sizes, by the
// distance over the element's longest edge.
struct SurfaceGap {
  static constexpr double kNone = std::numeric_limits<double>::infinity();
  double ratio = kNone;     // distance over the element's longest edge; kNone: no pair within near_ratio
  double distance = kNone;  // from the node to the element's flat facet
  int part = -1, other = -1;             // the node's surface and the element's
  Eigen::Index node = -1, element = -1;  // in the union's numbering
  bool inside = false;                   // the node lies behind its nearest element of the other surface
};

class CrossNearField {
 public:
  CrossNearField(const SurfaceSet& set, double near_ratio = kCrossNearRatio, int threads = 0);

  // The pairs on positions x (a union's rows): per surface pair whose boxes come within
  // near_ratio element sizes, a cell list of one's elements searched from the other's nodes.
  void find_pairs(const Points& x);
  // u_i += (1/8π) Σ_{pairs (i, e)} [∫_e G(x_i − y) q(y) dS_y − S.element_far_terms(e, x_i)], with
  // S the single layer on the union after its apply(x, q, ·).
  void correct(const Points& x, const Points& q, const SingleLayer& S, Points& u) const;

  const SurfaceGap& closest() const { return closest_; }
  // Nodes behind the outward side of their nearest element of another surface: inside it, where
  // that element's face (not an edge or a corner) is the nearest point.
  std::size_t inside_nodes() const { return inside_nodes_; }
  const SurfaceGap& deepest_inside() const { return deepest_inside_; }  // the farthest of them from the surface
  std::size_t pairs() const { return pair_element_.size(); }
  // Per node near another surface, its nearest element there (one entry per node and surface).
  const std::vector<SurfaceGap>& nearest() const { return nearest_; }
  double near_ratio() const { return near_ratio_; }
  double element_size(Eigen::Index e) const { return element_size_[static_cast<std::size_t>(e)]; }  // longest edge, at the last search

 private:
  std::vector<SurfacePart> parts_;
  Triangles tri_;
  double near_ratio_;
  int threads_;
  std::vector<Eigen::Index> pair_node_;     // nodes with pairs, ascending
  std::vector<std::size_t> pair_begin_;     // their pairs: [pair_begin_[k], pair_begin_[k + 1])
  std::vector<int> pair_element_;           // per node in ascending element order
  std::vector<double> element_size_;              // per element of the union: its longest edge
  std::vector<std::pair<Eigen::Index, int>> found_;  // scratch of find_pairs: (node, element)
  std::vector<int> candidates_;
  SurfaceGap closest_;
  std::size_t inside_nodes_ = 0;
  SurfaceGap deepest_inside_;
  std::vector<SurfaceGap> nearest_;
};

}  // namespace capsflow
