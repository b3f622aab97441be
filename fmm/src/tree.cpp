#include "capsflow/fmm/tree.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <utility>

namespace capsflow::fmm {

void sort_by_key(std::vector<KeyIndex>& kp, std::vector<KeyIndex>& scratch) {
  constexpr int kDigitBits = 11;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigitBits;
  std::uint64_t any = 0, all = ~std::uint64_t{0};
  for (const KeyIndex& e : kp) {
    any |= e.first;
    all &= e.first;
  }
  const std::uint64_t varying = any ^ all;  // the bits in which some keys differ
  scratch.resize(kp.size());
  std::vector<std::size_t> start(kBuckets);
  for (int shift = 0; shift < 64; shift += kDigitBits) {
    if (((varying >> shift) & (kBuckets - 1)) == 0) continue;  // one digit for every key: order kept
    std::fill(start.begin(), start.end(), 0);
    for (const KeyIndex& e : kp) ++start[(e.first >> shift) & (kBuckets - 1)];
    std::size_t at = 0;
    for (std::size_t& b : start) {
      const std::size_t n = b;
      b = at;
      at += n;
    }
    for (const KeyIndex& e : kp) scratch[start[(e.first >> shift) & (kBuckets - 1)]++] = e;
    kp.swap(scratch);
  }
}

namespace {
constexpr int kBits = 21;  // bits per axis in a Morton key

std::uint64_t spread3(std::uint64_t v) {  // 21 bits -> every third bit
  v &= 0x1fffffULL;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

std::uint64_t morton(std::uint64_t x, std::uint64_t y, std::uint64_t z) {
  return spread3(x) | (spread3(y) << 1) | (spread3(z) << 2);
}

// kp and scratch are the caller's buffers, kept across set-ups: allocating megabytes afresh at every
// set-up costs page faults that, on a virtual machine, were a tenth of the set-up.
void sort_points(const double* p, std::size_t n, const double origin[3], double scale,
                 std::vector<std::uint64_t>& keys, std::vector<std::size_t>& perm,
                 std::vector<double>& x, std::vector<double>& y, std::vector<double>& z,
                 std::vector<KeyIndex>& kp, std::vector<KeyIndex>& scratch, int threads) {
  kp.resize(n);
  const double cells = static_cast<double>(1u << kBits);
  const std::uint64_t maxc = (1u << kBits) - 1;
#pragma omp parallel for num_threads(threads) schedule(static)
  for (long i = 0; i < static_cast<long>(n); ++i) {
    std::uint64_t c[3];
    for (int d = 0; d < 3; ++d) {
      double v = (p[3 * i + d] - origin[d]) * scale * cells;
      v = std::min(std::max(v, 0.0), static_cast<double>(maxc));
      c[d] = static_cast<std::uint64_t>(v);
    }
    kp[i] = {morton(c[0], c[1], c[2]), static_cast<std::size_t>(i)};
  }
  sort_by_key(kp, scratch);  // = std::sort(kp): the indices are distinct and ascending
  keys.resize(n); perm.resize(n); x.resize(n); y.resize(n); z.resize(n);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (long i = 0; i < static_cast<long>(n); ++i) {
    keys[i] = kp[i].first;
    const std::size_t j = kp[i].second;
    perm[i] = j;
    x[i] = (p[3 * j] - origin[0]) * scale;
    y[i] = (p[3 * j + 1] - origin[1]) * scale;
    z[i] = (p[3 * j + 2] - origin[2]) * scale;
  }
}
}  // namespace

int v_offset_index(int dx, int dy, int dz) {
  if (std::abs(dx) > 3 || std::abs(dy) > 3 || std::abs(dz) > 3) return -1;
  if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) < 2) return -1;
  // enumerate the 7^3 cube in order, skipping the inner 3^3
  static const std::array<int, 343> table = [] {
    std::array<int, 343> t{};
    int k = 0;
    for (int i = 0; i < 343; ++i) {
      const int a = i % 7 - 3, b = (i / 7) % 7 - 3, c = i / 49 - 3;
      t[i] = (std::max({std::abs(a), std::abs(b), std::abs(c)}) >= 2) ? k++ : -1;
    }
    return t;
  }();
  return table[(dx + 3) + 7 * (dy + 3) + 49 * (dz + 3)];
}

bool Tree::adjacent(int a, int b) const {
  const Node& A = nodes[a];
  const Node& B = nodes[b];
  const int sa = kMaxLevel + 1 - A.level, sb = kMaxLevel + 1 - B.level;
  const long wa = 1L << sa, wb = 1L << sb;
  const long ai[3] = {static_cast<long>(A.ix) << sa, static_cast<long>(A.iy) << sa, static_cast<long>(A.iz) << sa};
  const long bi[3] = {static_cast<long>(B.ix) << sb, static_cast<long>(B.iy) << sb, static_cast<long>(B.iz) << sb};
  for (int d = 0; d < 3; ++d)
    if (ai[d] > bi[d] + wb || bi[d] > ai[d] + wa) return false;
  return true;
}

void Tree::build(const double* src, std::size_t n_src, const double* trg, std::size_t n_trg,
                 int leaf_size, int threads) {
  if (threads <= 0) threads = omp_get_max_threads();
  if (leaf_size < 1) leaf_size = 1;
  // bounding cube of all points
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  bool first = true;
  auto grow = [&](const double* p, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i)
      for (int d = 0; d < 3; ++d) {
        const double v = p[3 * i + d];
        if (first) { lo[d] = hi[d] = v; }
        lo[d] = std::min(lo[d], v);
        hi[d] = std::max(hi[d], v);
        if (d == 2) first = false;
      }
  };
  grow(src, n_src);
  grow(trg, n_trg);
  double ext = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  if (!(ext > 0)) ext = 1.0;
  length = ext * (1 + 1e-9);
  for (int d = 0; d < 3; ++d) origin[d] = lo[d] - 0.5 * (length - (hi[d] - lo[d]));
  const double scale = 1.0 / length;

  std::vector<std::uint64_t>& skey = src_key_;
  std::vector<std::uint64_t>& tkey = trg_key_;
  sort_points(src, n_src, origin, scale, skey, src_perm, sx, sy, sz, sort_buffer_, sort_scratch_, threads);
  sort_points(trg, n_trg, origin, scale, tkey, trg_perm, tx, ty, tz, sort_buffer_, sort_scratch_, threads);

  nodes.clear();
  leaves.clear();
  level_begin.assign(1, 0);
  Node root;
  root.se = n_src;
  root.te = n_trg;
  nodes.push_back(root);
  for (int l = 0;; ++l) {
    const std::size_t b = level_begin[l], e = nodes.size();
    level_begin.push_back(e);
    if (b == e) { level_begin.pop_back(); break; }
    for (std::size_t n = b; n < e; ++n) {
      Node nd = nodes[n];
      const bool split = l < kMaxLevel && (nd.nsrc() > static_cast<std::size_t>(leaf_size) ||
                                           nd.ntrg() > static_cast<std::size_t>(leaf_size));
      if (!split) { leaves.push_back(static_cast<int>(n)); continue; }
      nodes[n].leaf = false;
      const int shift = 3 * (kBits - l - 1);
      std::size_t s0 = nd.sb, t0 = nd.tb;
      for (int o = 0; o < 8; ++o) {
        auto digit_le = [&](std::uint64_t k) { return static_cast<int>((k >> shift) & 7) <= o; };
        // within the node, keys share the prefix and are sorted, so the digit is monotone
        const std::size_t s1 = static_cast<std::size_t>(
            std::partition_point(skey.begin() + s0, skey.begin() + nd.se, digit_le) - skey.begin());
        const std::size_t t1 = static_cast<std::size_t>(
            std::partition_point(tkey.begin() + t0, tkey.begin() + nd.te, digit_le) - tkey.begin());
        if (s1 > s0 || t1 > t0) {
          Node c;
          c.level = l + 1;
          c.ix = 2 * nd.ix + (o & 1);
          c.iy = 2 * nd.iy + ((o >> 1) & 1);
          c.iz = 2 * nd.iz + ((o >> 2) & 1);
          c.parent = static_cast<int>(n);
          c.octant = o;
          c.sb = s0; c.se = s1; c.tb = t0; c.te = t1;
          nodes[n].child[o] = static_cast<int>(nodes.size());
          nodes.push_back(c);
        }
        s0 = s1;
        t0 = t1;
      }
    }
  }
  build_lists(threads);
}

void Tree::build_lists(int threads) {
  const int nn = static_cast<int>(nodes.size());
  // colleagues: same-level adjacent nodes (including self), from the parent's colleagues
  std::vector<std::vector<int>> coll(nn);
  coll[0] = {0};
  for (int l = 1; l < levels(); ++l) {
#pragma omp parallel for num_threads(threads) schedule(dynamic, 64)
    for (long n = static_cast<long>(level_begin[l]); n < static_cast<long>(level_begin[l + 1]); ++n) {
      const Node& B = nodes[n];
      for (int pc : coll[B.parent])
        for (int c : nodes[pc].child)
          if (c >= 0 && std::abs(nodes[c].ix - B.ix) <= 1 && std::abs(nodes[c].iy - B.iy) <= 1 &&
              std::abs(nodes[c].iz - B.iz) <= 1)
            coll[n].push_back(c);
    }
  }
  std::vector<std::vector<int>> u(nn), v(nn), vo(nn), w(nn);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 16)
  for (int n = 0; n < nn; ++n) {
    const Node& B = nodes[n];
    // V list
    if (B.parent >= 0 && B.ntrg() > 0) {
      for (int pc : coll[B.parent])
        for (int c : nodes[pc].child) {
          if (c < 0 || nodes[c].nsrc() == 0) continue;
          const int dx = B.ix - nodes[c].ix, dy = B.iy - nodes[c].iy, dz = B.iz - nodes[c].iz;
          if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) >= 2) {
            v[n].push_back(c);
            vo[n].push_back(v_offset_index(dx, dy, dz));
          }
        }
    }
    if (!B.leaf) continue;
    // U (same level and finer) and structural W
    std::vector<int> stack;
    for (int c : coll[n]) {
      if (c == n || nodes[c].leaf) { u[n].push_back(c); continue; }
      stack.push_back(c);
      while (!stack.empty()) {
        const int a = stack.back();
        stack.pop_back();
        for (int d : nodes[a].child) {
          if (d < 0) continue;
          if (adjacent(d, n)) {
            if (nodes[d].leaf) u[n].push_back(d); else stack.push_back(d);
          } else {
            w[n].push_back(d);
          }
        }
      }
    }
    // coarser adjacent leaves: leaf colleagues of ancestors
    for (int p = B.parent; p >= 0; p = nodes[p].parent)
      for (int c : coll[p])
        if (nodes[c].leaf && adjacent(c, n)) u[n].push_back(c);
  }
  // X = transpose of structural W (source leaf A, target node B)
  std::vector<std::vector<int>> x(nn);
  for (int a = 0; a < nn; ++a)
    if (nodes[a].leaf && nodes[a].nsrc() > 0)
      for (int b : w[a])
        if (nodes[b].ntrg() > 0) x[b].push_back(a);
  // filter and pack
  auto pack = [&](std::vector<std::vector<int>>& rows, Csr& out, bool need_trg_leaf) {
    out.begin.assign(nn + 1, 0);
    out.item.clear();
    for (int n = 0; n < nn; ++n) {
      if (!need_trg_leaf || nodes[n].ntrg() > 0)
        for (int a : rows[n])
          if (nodes[a].nsrc() > 0) out.item.push_back(a);
      out.begin[n + 1] = out.item.size();
    }
  };
  pack(u, U, true);
  pack(w, W, true);
  pack(x, X, false);
  V.begin.assign(nn + 1, 0);
  V.item.clear();
  v_offset.clear();
  for (int n = 0; n < nn; ++n) {
    V.item.insert(V.item.end(), v[n].begin(), v[n].end());
    v_offset.insert(v_offset.end(), vo[n].begin(), vo[n].end());
    V.begin[n + 1] = V.item.size();
  }
}

}  // namespace capsflow::fmm
