#pragma once
// capsflow::fmm::Tree — adaptive octree over sources and targets, with KIFMM interaction lists.
//
// Lifetime: rebuilt whenever the points move (every time-integration stage). Kernel-independent.
// - Coordinates are normalised to the unit root cube [0,1)^3: x' = (x − origin)/length.
//   Level-l boxes have half-width 0.5·2^-l.
// - Points are Morton-sorted (21 bits per axis); every node owns contiguous ranges of the sorted
//   sources [sb,se) and targets [tb,te). A box is split while it holds more than leaf_size
//   sources or more than leaf_size targets (and level < max_level). Empty boxes are discarded;
//   no 2:1 balance.
// - Nodes are stored level by level (level_begin[l] .. level_begin[l+1]).
// - Lists (Ying, Biros & Zorin 2004), filtered so that every entry moves something:
//     U(B), leaf B with targets: leaves adjacent to B (incl. B) with sources        -> P2P
//     V(B), B with targets: children of parent's colleagues, not adjacent, with sources -> M2L
//     W(B), leaf B with targets: descendants of colleagues not adjacent to B whose
//           parent is adjacent, with sources                                     -> M2P or P2P
//     X(B), B with targets: leaves A with sources such that B ∈ W(A)             -> P2L or P2P
#include <cstddef>
#include <cstdint>
#include <vector>

#include "capsflow/fmm/key_sort.hpp"

namespace capsflow::fmm {

struct Csr {
  std::vector<std::size_t> begin{0};  // size n+1
  std::vector<int> item;
  std::size_t size(int i) const { return begin[i + 1] - begin[i]; }
};

struct Node {
  int level = 0;
  int ix = 0, iy = 0, iz = 0;  // integer anchor at this level
  int parent = -1;
  int octant = 0;              // position in the parent
  int child[8] = {-1, -1, -1, -1, -1, -1, -1, -1};
  std::size_t sb = 0, se = 0, tb = 0, te = 0;
  bool leaf = true;
  std::size_t nsrc() const { return se - sb; }
  std::size_t ntrg() const { return te - tb; }
};

class Tree {
 public:
  static constexpr int kMaxLevel = 20;

  /// Build the tree (sorting, normalisation) and the interaction lists.
  void build(const double* src, std::size_t n_src, const double* trg, std::size_t n_trg,
             int leaf_size, int threads);

  // normalisation
  double origin[3] = {0, 0, 0};
  double length = 1.0;
  static double half_width(int level) { return 0.5 / static_cast<double>(1u << level); }
  void center(int n, double c[3]) const {
    const Node& b = nodes[n];
    const double w = 1.0 / static_cast<double>(1u << b.level);
    c[0] = (b.ix + 0.5) * w; c[1] = (b.iy + 0.5) * w; c[2] = (b.iz + 0.5) * w;
  }

  std::vector<Node> nodes;
  std::vector<std::size_t> level_begin;  // nodes of level l: [level_begin[l], level_begin[l+1])
  int levels() const { return static_cast<int>(level_begin.size()) - 1; }
  std::vector<int> leaves;               // all leaves

  // Morton-sorted, normalised points (structure of arrays) and sorted -> caller index maps.
  std::vector<double> sx, sy, sz, tx, ty, tz;
  std::vector<std::size_t> src_perm, trg_perm;

  // interaction lists, indexed by node id (empty rows where not applicable)
  Csr U, V, W, X;
  std::vector<int> v_offset;  // parallel to V.item: index of the relative offset in [-3,3]^3 \ [-1,1]^3

  /// true if the closed boxes a and b touch or overlap
  bool adjacent(int a, int b) const;

 private:
  void build_lists(int threads);
  // Buffers of the sort, kept across builds (tree.cpp's sort_points).
  std::vector<std::uint64_t> src_key_, trg_key_;
  std::vector<KeyIndex> sort_buffer_, sort_scratch_;
};

/// Index of a V-list offset (dx,dy,dz) ∈ [-3,3]^3 with max |d| ≥ 2 (316 values), or -1.
int v_offset_index(int dx, int dy, int dz);
constexpr int kNumVOffsets = 316;

}  // namespace capsflow::fmm
