#pragma once
// Implementation of capsflow::fmm::Fmm<Kernel> (included by fmm.hpp; templated so that tests can
// instantiate it with their own kernels, e.g. a counting kernel).
//
// Data per evaluation (sorted order): f_ densities, u_ outputs, and per node surface vectors
// (column-major, one column per node, nodes level by level):
//   ue_ upward equivalent density, cu_ upward reference check potential,
//   rc_ downward reference check potential, de_ downward equivalent density.
// Kernels: Kernel (the sources' own, "P" below) in P2M, P2L and the direct near field; Up
// (upward equivalent) in M2M, M2L and M2P; Down (downward equivalent) in L2L and L2P
// (equivalent.hpp). Check potentials of a box of half-width r are stored times r^{-h_E}.
// Parallelism: owner computes everywhere (each thread writes only its own nodes' columns or its own
// leaf's targets); no atomics. Dense operator products are blocked GEMMs over the columns of a level.
#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "capsflow/fmm/equivalent.hpp"
#include "capsflow/fmm/p2p.hpp"
#include "capsflow/fmm/p2p_mixed.hpp"

namespace capsflow::fmm {
namespace detail {

inline double wall_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// C(:, 0:ncols) (+)= A * B(:, 0:ncols), column-major with leading dimensions. Parallel over
/// row blocks of A: each thread packs only its own slice of the (large) operator A, and because
/// the calls run inside a team of threads Eigen does not start its own parallel GEMM.
inline void par_gemm(const Eigen::MatrixXd& A, const double* B, std::size_t ldb, double* C,
                     std::size_t ldc, std::size_t ncols, bool accumulate, int threads) {
  using CMap = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
  using MMap = Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
  if (ncols == 0) return;
  const long m = A.rows();
  const int nthr = std::max(1, threads);
  CMap Bm(B, A.cols(), static_cast<long>(ncols), Eigen::OuterStride<>(static_cast<long>(ldb)));
#pragma omp parallel num_threads(nthr)
  {
    const int me = omp_get_thread_num(), nt = omp_get_num_threads();
    // row blocks rounded to 8 (one AVX-512 vector)
    const long r0 = std::min(m, (m * me / nt) / 8 * 8);
    const long r1 = me + 1 == nt ? m : std::min(m, (m * (me + 1) / nt) / 8 * 8);
    if (r1 > r0) {
      MMap Cm(C + r0, r1 - r0, static_cast<long>(ncols), Eigen::OuterStride<>(static_cast<long>(ldc)));
      if (accumulate) Cm.noalias() += A.middleRows(r0, r1 - r0) * Bm;
      else Cm.noalias() = A.middleRows(r0, r1 - r0) * Bm;
    }
  }
}

/// out(:, 0:ncols) = pinv · in(:, 0:ncols) with pinv = vs·ut applied factor by factor (never
/// as one product: see PinvFactors in operators.hpp). work is resized to rank × ncols.
inline void apply_pinv(const PinvFactors& pinv, const double* in, std::size_t ldin, double* out,
                       std::size_t ldout, std::size_t ncols, std::vector<double>& work, int threads) {
  if (ncols == 0) return;
  const std::size_t r = static_cast<std::size_t>(pinv.ut.rows());
  if (work.size() < r * ncols) work.resize(r * ncols);
  par_gemm(pinv.ut, in, ldin, work.data(), r, ncols, false, threads);
  par_gemm(pinv.vs, work.data(), r, out, ldout, ncols, false, threads);
}

/// Density arrays (one per component of E) of one box's equivalent surface (n points), in true
/// units: a component with a degree shift is stored times rho^shift (equivalent.hpp) and is
/// rescaled into scratch (E::src_dim·n doubles; unused, may be null, without shifts); the others
/// point into the stored vector.
template <class E>
inline void true_equivalent_density(const double* stored, std::size_t n, double rho, double* scratch,
                                    const double** f) {
  for (int b = 0; b < E::src_dim; ++b) {
    f[b] = stored + b * n;
    if constexpr (has_degree_shift<E>()) {
      if (degree_shift<E>(b) == 0) continue;
      const double a = std::pow(rho, -degree_shift<E>(b));
      double* sc = scratch + b * n;
      for (std::size_t k = 0; k < n; ++k) sc[k] = a * f[b][k];
      f[b] = sc;
    }
  }
}

}  // namespace detail

template <class Kernel>
Fmm<Kernel>::Fmm(const FmmOptions& opt) : opt_(opt) {
  const int p = opt.order > 0 ? opt.order : order_for_tolerance<Kernel>(opt.tolerance);
  ops_ = std::make_shared<const Operators<Kernel>>(p, opt.cache_dir);
  leaf_size_ = opt.leaf_size > 0 ? opt.leaf_size : default_leaf_size<Kernel>(p);
  threads_ = opt.threads > 0 ? opt.threads : omp_get_max_threads();
  fast_rsqrt_ = !opt.exact_near_field && p <= kFastRsqrtMaxOrder;
  single_pairs_ = opt.single_precision_pairs && !opt.exact_near_field && simd::kHasSinglePrecisionPairs;
}

template <class Kernel>
Fmm<Kernel>::Fmm(const FmmOptions& opt, std::shared_ptr<const Operators<Kernel>> ops)
    : opt_(opt), ops_(std::move(ops)) {
  if (!ops_) throw std::invalid_argument("capsflow::fmm::Fmm: null operators");
  leaf_size_ = opt.leaf_size > 0 ? opt.leaf_size : default_leaf_size<Kernel>(ops_->order());
  threads_ = opt.threads > 0 ? opt.threads : omp_get_max_threads();
  fast_rsqrt_ = !opt.exact_near_field && ops_->order() <= kFastRsqrtMaxOrder;
  single_pairs_ = opt.single_precision_pairs && !opt.exact_near_field && simd::kHasSinglePrecisionPairs;
}

template <class Kernel>
void Fmm<Kernel>::setup(const double* src, std::size_t n_src, const double* trg, std::size_t n_trg) {
  const double t0 = detail::wall_now();
  n_src_ = n_src;
  n_trg_ = n_trg;
  tree_.build(src, n_src, trg, n_trg, leaf_size_, threads_);
  const std::size_t nn = tree_.nodes.size(), n = static_cast<std::size_t>(ops_->nsurf());
  const std::size_t ldu = Up::src_dim * n, ldd = Down::src_dim * n, ldc = Kernel::trg_dim * n;
  ue_.assign(ldu * nn, 0.0);
  de_.assign(ldd * nn, 0.0);
  cu_.assign(ldc * nn, 0.0);
  rc_.assign(ldc * nn, 0.0);
  x_direct_.assign(nn, 0);
  for (std::size_t b = 0; b < nn; ++b)
    x_direct_[b] = tree_.X.size(static_cast<int>(b)) > 0 && tree_.nodes[b].ntrg() <= n;
  has_setup_ = true;
  t_ = FmmTimings{};
  t_.tree = detail::wall_now() - t0;
  t_.setup_total = t_.tree;
}

template <class Kernel>
int Fmm<Kernel>::group_size(int n_densities) const {
  // densities evaluated together share every pass; the per-node surface vectors (4 arrays)
  // grow with the group, so the group is capped at kMaxSharedDensities and at ~2 GB of them
  const double per_density = sizeof(double) * (Up::src_dim + Down::src_dim + 2.0 * Kernel::trg_dim) *
                             static_cast<double>(ops_->nsurf()) * static_cast<double>(tree_.nodes.size());
  int g = std::min(n_densities, kMaxSharedDensities);
  while (g > 1 && g * per_density > 2e9) --g;
  return std::max(1, g);
}

template <class Kernel>
void Fmm<Kernel>::evaluate(const double* density, double* out, int n_densities) {
  if (!has_setup_) throw std::logic_error("capsflow::fmm::Fmm::evaluate called before setup");
  if (n_densities < 0) throw std::invalid_argument("capsflow::fmm::Fmm::evaluate: n_densities < 0");
  const double setup_tree = t_.tree, setup_total = t_.setup_total;
  t_ = FmmTimings{};
  t_.tree = setup_tree;
  t_.setup_total = setup_total;
  const double t0 = detail::wall_now();
  const int g = group_size(n_densities);
  for (int d = 0; d < n_densities; d += g)
    evaluate_group(density + static_cast<std::size_t>(d) * n_src_ * Kernel::src_dim,
                   out + static_cast<std::size_t>(d) * n_trg_ * Kernel::trg_dim, std::min(g, n_densities - d));
  t_.eval_total = detail::wall_now() - t0;
}

template <class Kernel>
void Fmm<Kernel>::evaluate_group(const double* density, double* out, int nd) {
  constexpr int SD = Kernel::src_dim, TD = Kernel::trg_dim;
  double t = detail::wall_now();
  std::fill(out, out + n_trg_ * TD * nd, 0.0);
  if (n_trg_ == 0 || n_src_ == 0) return;
  nd_ = nd;
  const std::size_t nn = tree_.nodes.size(), n = static_cast<std::size_t>(ops_->nsurf());
  const std::size_t ldu = Up::src_dim * n, ldd = Down::src_dim * n, ldc = TD * n;
  if (ue_.size() != ldu * nn * nd) {
    ue_.assign(ldu * nn * nd, 0.0);
    de_.assign(ldd * nn * nd, 0.0);
    cu_.assign(ldc * nn * nd, 0.0);
    rc_.assign(ldc * nn * nd, 0.0);
  }
  f_.resize(SD * n_src_ * nd);
  u_.assign(TD * n_trg_ * nd, 0.0);
  const auto& sp = tree_.src_perm;
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (long i = 0; i < static_cast<long>(n_src_); ++i)
    for (int d = 0; d < nd; ++d)
      for (int k = 0; k < SD; ++k)
        f_[(d * SD + k) * n_src_ + i] = density[d * SD * n_src_ + SD * sp[i] + k];
  t_.other += detail::wall_now() - t;

  upward();
  downward_checks();
  downward();
  near_field();
  local_to_targets();

  t = detail::wall_now();
  const double s = std::pow(tree_.length, Kernel::homogeneity);
  const auto& tp = tree_.trg_perm;
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (long i = 0; i < static_cast<long>(n_trg_); ++i)
    for (int d = 0; d < nd; ++d)
      for (int k = 0; k < TD; ++k) out[d * TD * n_trg_ + TD * tp[i] + k] = s * u_[(d * TD + k) * n_trg_ + i];
  t_.other += detail::wall_now() - t;
}

template <class Kernel>
void Fmm<Kernel>::upward() {
  constexpr int SD = Kernel::src_dim, TD = Kernel::trg_dim;
  const Operators<Kernel>& op = *ops_;
  const int n = op.nsurf(), nd = nd_;
  const std::size_t ldu = Up::src_dim * n, ldc = TD * n;
  const Tree& T = tree_;
  const int L = T.levels();
  std::fill(cu_.begin(), cu_.end(), 0.0);
  std::fill(ue_.begin(), ue_.end(), 0.0);
  for (int l = L - 1; l >= 2; --l) {
    const std::size_t lb = T.level_begin[l], le = T.level_begin[l + 1];
    double t = detail::wall_now();
    // P2M: leaf sources -> upward check surface (2.95 r), reference-scaled by r^{-h_E}
    const double r = Tree::half_width(l);
    const double sc = Kernel::scale() * std::pow(r, -Up::homogeneity);
#pragma omp parallel num_threads(threads_)
    {
      std::vector<double> px(n), py(n), pz(n);
      std::vector<const double*> f(SD * nd);
      std::vector<double*> u(TD * nd);
#pragma omp for schedule(dynamic, 4)
      for (long b = static_cast<long>(lb); b < static_cast<long>(le); ++b) {
        const Node& B = T.nodes[b];
        if (!B.leaf || B.nsrc() == 0) continue;
        double c[3];
        T.center(static_cast<int>(b), c);
        op.surface().place(c, kRadOuter * r, px.data(), py.data(), pz.data());
        for (int k = 0; k < SD * nd; ++k) f[k] = f_.data() + k * n_src_ + B.sb;
        for (int d = 0; d < nd; ++d)
          for (int k = 0; k < TD; ++k) u[d * TD + k] = cu_.data() + (b * nd + d) * ldc + k * n;
        p2p_multi<Kernel, 2, false>(nd, px.data(), py.data(), pz.data(), n, T.sx.data() + B.sb,
                                    T.sy.data() + B.sb, T.sz.data() + B.sb, f.data(), B.nsrc(), u.data(), sc);
      }
    }
    t_.p2m += detail::wall_now() - t;
    t = detail::wall_now();
    // M2M: children (level l+1) -> parents' reference check, batched per octant
    if (l + 1 < L) {
      const std::size_t cb = T.level_begin[l + 1], ce = T.level_begin[l + 2];
      for (int o = 0; o < 8; ++o) {
        std::vector<int> kids;
        for (std::size_t c = cb; c < ce; ++c)
          if (T.nodes[c].octant == o && T.nodes[c].nsrc() > 0) kids.push_back(static_cast<int>(c));
        if (kids.empty()) continue;
        const std::size_t nk = kids.size() * nd;
        std::vector<double> X(ldu * nk), Y(ldc * nk);
        for (std::size_t j = 0; j < kids.size(); ++j)
          std::copy_n(ue_.data() + kids[j] * nd * ldu, nd * ldu, X.data() + j * nd * ldu);
        detail::par_gemm(op.m2m(o), X.data(), ldu, Y.data(), ldc, nk, false, threads_);
        for (std::size_t j = 0; j < kids.size(); ++j) {
          double* dst = cu_.data() + T.nodes[kids[j]].parent * nd * ldc;
          const double* srcv = Y.data() + j * nd * ldc;
          for (std::size_t i = 0; i < nd * ldc; ++i) dst[i] += srcv[i];
        }
      }
    }
    // check -> equivalent for the whole level
    detail::apply_pinv(op.uc2ue(), cu_.data() + lb * nd * ldc, ldc, ue_.data() + lb * nd * ldu, ldu,
                       (le - lb) * nd, pinv_work_, threads_);
    t_.m2m += detail::wall_now() - t;
  }
}

template <class Kernel>
void Fmm<Kernel>::downward_checks() {
  constexpr int SD = Kernel::src_dim, TD = Kernel::trg_dim, SU = Up::src_dim;
  const Operators<Kernel>& op = *ops_;
  const M2lFft& fft = op.m2l();
  const int n = op.nsurf(), nd = nd_;
  const std::size_t ldu = SU * n, ldc = TD * n;
  const Tree& T = tree_;
  const int L = T.levels();
  std::fill(rc_.begin(), rc_.end(), 0.0);
  double t = detail::wall_now();
  const std::size_t sss = fft.src_spec_size(), tss = fft.trg_spec_size();
  const int CH = M2lFft::kChunk;
  // With nd densities every box stands for nd "virtual" boxes (box-major, density-minor): the
  // spectra of one level hold nsrc·nd sources and ntrg·nd targets, and each V pair (t, s)
  // becomes nd pairs (t·nd + d, s·nd + d) streaming through the same kernel block.
  for (int l = 2; l < L; ++l) {
    const std::size_t lb = T.level_begin[l], le = T.level_begin[l + 1];
    std::vector<int> loc(le - lb, -1), srcs, trgs;
    for (std::size_t b = lb; b < le; ++b) {
      if (T.nodes[b].nsrc() > 0) { loc[b - lb] = static_cast<int>(srcs.size()); srcs.push_back(static_cast<int>(b)); }
      if (T.V.size(static_cast<int>(b)) > 0) trgs.push_back(static_cast<int>(b));
    }
    if (trgs.empty()) continue;
    const std::size_t nvs = srcs.size() * nd, nvt = trgs.size() * nd;
    if (sspec_.size() < sss * nvs) sspec_.resize(sss * nvs);
    if (tspec_.size() < tss * nvt) tspec_.resize(tss * nvt);
    double* const sspec = sspec_.data();
    double* const tspec = tspec_.data();
    // per target: source local indices and offsets, and a work prefix for balancing
    std::vector<std::size_t> vb(trgs.size() + 1, 0);
    for (std::size_t j = 0; j < trgs.size(); ++j) vb[j + 1] = vb[j] + T.V.size(trgs[j]);
    std::vector<int> vsrc(vb.back()), voff(vb.back());
    for (std::size_t j = 0; j < trgs.size(); ++j)
      for (std::size_t v = T.V.begin[trgs[j]], q = vb[j]; v < T.V.begin[trgs[j] + 1]; ++v, ++q) {
        vsrc[q] = loc[T.V.item[v] - lb];
        voff[q] = T.v_offset[v];
      }
#pragma omp parallel num_threads(threads_)
    {
      M2lFft::Work w(fft);
      const double tf0 = detail::wall_now();
      constexpr int G = M2lFft::kBatch;
#pragma omp for schedule(dynamic, 1)
      for (long j0 = 0; j0 < static_cast<long>(nvs); j0 += G) {
        const int g = static_cast<int>(std::min<std::size_t>(G, nvs - j0));
        const double* ue[G];
        for (int i = 0; i < g; ++i) {
          const std::size_t jv = j0 + i;
          ue[i] = ue_.data() + (srcs[jv / nd] * nd + jv % nd) * ldu;
        }
        fft.forward(ue, g, sspec, j0, nvs, w);
      }
      const double tf1 = detail::wall_now();
      // owner computes: a contiguous range of targets with equal V-list work per thread
      const int nth = omp_get_num_threads(), me = omp_get_thread_num();
      const std::size_t w0 = vb.back() * me / nth, w1 = vb.back() * (me + 1) / nth;
      const std::size_t j0 = static_cast<std::size_t>(std::lower_bound(vb.begin(), vb.end() - 1, w0) - vb.begin());
      const std::size_t j1 = me + 1 == nth ? trgs.size()
          : static_cast<std::size_t>(std::lower_bound(vb.begin(), vb.end() - 1, w1) - vb.begin());
      const std::size_t sblk = static_cast<std::size_t>(SU) * 2 * CH * nvs;
      const std::size_t tblk = static_cast<std::size_t>(TD) * 2 * CH * nvt;
      for (int c = 0; c < fft.nchunk(); ++c)
        std::fill(tspec + c * tblk + j0 * nd * TD * 2 * CH, tspec + c * tblk + j1 * nd * TD * 2 * CH, 0.0);
      // this thread's (target, source) pairs grouped by V offset: each kernel block is loaded once
      // per chunk and offset, the pairs stream through it
      std::vector<std::size_t> ob(kNumVOffsets + 1, 0);
      for (std::size_t q = vb[j0]; q < vb[j1]; ++q) ob[voff[q] + 1] += nd;
      for (int o = 0; o < kNumVOffsets; ++o) ob[o + 1] += ob[o];
      std::vector<int> pairs(2 * nd * (vb[j1] - vb[j0]));
      {
        std::vector<std::size_t> fill(ob.begin(), ob.end() - 1);
        for (std::size_t j = j0; j < j1; ++j)
          for (std::size_t q = vb[j]; q < vb[j + 1]; ++q)
            for (int d = 0; d < nd; ++d) {
              const std::size_t at = fill[voff[q]]++;
              pairs[2 * at] = static_cast<int>(j * nd + d);
              pairs[2 * at + 1] = vsrc[q] * nd + d;
            }
      }
      for (int c = 0; c < fft.nchunk(); ++c)
        for (int o = 0; o < kNumVOffsets; ++o)
          if (ob[o + 1] > ob[o])
            fft.template hadamard_pairs<TD, SU>(c, o, pairs.data() + 2 * ob[o], ob[o + 1] - ob[o],
                                                sspec + c * sblk, tspec + c * tblk);
      const double tf2 = detail::wall_now();
      for (std::size_t jv = j0 * nd; jv < j1 * nd; jv += G) {
        const int g = static_cast<int>(std::min<std::size_t>(G, j1 * nd - jv));
        double* chk[G];
        for (int i = 0; i < g; ++i) chk[i] = rc_.data() + (trgs[(jv + i) / nd] * nd + (jv + i) % nd) * ldc;
        fft.backward(tspec, jv, g, nvt, chk, w);
      }
      if (me == 0) {
        t_.m2l_fft += (tf1 - tf0) + (detail::wall_now() - tf2);
        t_.m2l_hadamard += tf2 - tf1;
      }
    }
  }
  t_.m2l += detail::wall_now() - t;
  // X list by P2L: sources of A -> downward check surface (1.05 r) of B, reference-scaled by r^{-h_E}
  t = detail::wall_now();
#pragma omp parallel num_threads(threads_)
  {
    std::vector<double> px(n), py(n), pz(n);
    std::vector<const double*> f(SD * nd);
    std::vector<double*> u(TD * nd);
#pragma omp for schedule(dynamic, 4)
    for (long b = 0; b < static_cast<long>(T.nodes.size()); ++b) {
      if (x_direct_[b] || T.X.size(static_cast<int>(b)) == 0) continue;
      const int lev = T.nodes[b].level;
      const double r = Tree::half_width(lev);
      double c[3];
      T.center(static_cast<int>(b), c);
      op.surface().place(c, kRadInner * r, px.data(), py.data(), pz.data());
      for (int d = 0; d < nd; ++d)
        for (int k = 0; k < TD; ++k) u[d * TD + k] = rc_.data() + (b * nd + d) * ldc + k * n;
      for (std::size_t x = T.X.begin[b]; x < T.X.begin[b + 1]; ++x) {
        const Node& A = T.nodes[T.X.item[x]];
        for (int k = 0; k < SD * nd; ++k) f[k] = f_.data() + k * n_src_ + A.sb;
        p2p_multi<Kernel, 2, false>(nd, px.data(), py.data(), pz.data(), n, T.sx.data() + A.sb,
                                    T.sy.data() + A.sb, T.sz.data() + A.sb, f.data(), A.nsrc(), u.data(),
                                    Kernel::scale() * std::pow(r, -Up::homogeneity));
      }
    }
  }
  t_.x_list += detail::wall_now() - t;
}

template <class Kernel>
void Fmm<Kernel>::downward() {
  constexpr int TD = Kernel::trg_dim;
  const Operators<Kernel>& op = *ops_;
  const int n = op.nsurf(), nd = nd_;
  const std::size_t ldd = Down::src_dim * n, ldc = TD * n;
  const Tree& T = tree_;
  const int L = T.levels();
  const double t = detail::wall_now();
  for (int l = 2; l < L; ++l) {
    const std::size_t lb = T.level_begin[l], le = T.level_begin[l + 1];
    if (l >= 3) {
      for (int o = 0; o < 8; ++o) {
        std::vector<int> kids;
        for (std::size_t c = lb; c < le; ++c)
          if (T.nodes[c].octant == o && T.nodes[c].ntrg() > 0) kids.push_back(static_cast<int>(c));
        if (kids.empty()) continue;
        const std::size_t nk = kids.size() * nd;
        std::vector<double> X(ldd * nk), Y(ldc * nk);
        for (std::size_t j = 0; j < kids.size(); ++j)
          std::copy_n(de_.data() + T.nodes[kids[j]].parent * nd * ldd, nd * ldd, X.data() + j * nd * ldd);
        detail::par_gemm(op.l2l(o), X.data(), ldd, Y.data(), ldc, nk, false, threads_);
        for (std::size_t j = 0; j < kids.size(); ++j) {
          double* dst = rc_.data() + kids[j] * nd * ldc;
          const double* s = Y.data() + j * nd * ldc;
          for (std::size_t i = 0; i < nd * ldc; ++i) dst[i] += s[i];
        }
      }
    }
    detail::apply_pinv(op.dc2de(), rc_.data() + lb * nd * ldc, ldc, de_.data() + lb * nd * ldd, ldd,
                       (le - lb) * nd, pinv_work_, threads_);
  }
  t_.l2l += detail::wall_now() - t;
}

template <class Kernel>
void Fmm<Kernel>::near_field() {
  constexpr int SD = Kernel::src_dim, TD = Kernel::trg_dim, SU = Up::src_dim;
  const Operators<Kernel>& op = *ops_;
  const int n = op.nsurf(), nd = nd_;
  const std::size_t ldu = SU * n;
  const Tree& T = tree_;
  const double t = detail::wall_now();
  const auto& leaves = T.leaves;
#pragma omp parallel num_threads(threads_)
  {
    std::vector<double> px(n), py(n), pz(n);
    std::vector<const double*> f(std::max(SD, SU) * nd);
    std::vector<double> scaled(has_degree_shift<Up>() ? ldu * nd : 0);
    std::vector<double*> u(TD * nd);
#pragma omp for schedule(dynamic, 1)
    for (long li = 0; li < static_cast<long>(leaves.size()); ++li) {
      const int b = leaves[li];
      const Node& B = T.nodes[b];
      if (B.ntrg() == 0) continue;
      const double *tx = T.tx.data() + B.tb, *ty = T.ty.data() + B.tb, *tz = T.tz.data() + B.tb;
      for (int k = 0; k < TD * nd; ++k) u[k] = u_.data() + k * n_trg_ + B.tb;
      // Points of distinct boxes have distinct Morton keys, hence never coincide: only the
      // leaf's own sources need the r = 0 mask.
      auto direct_from = [&](const Node& A) {
        for (int k = 0; k < SD * nd; ++k) f[k] = f_.data() + k * n_src_ + A.sb;
        const double *sx = T.sx.data() + A.sb, *sy = T.sy.data() + A.sb, *sz = T.sz.data() + A.sb;
        const bool self = &A == &B;
        const double sc = Kernel::scale();
        if (single_pairs_ && nd == 1) {
          if (self) p2p_mixed<Kernel, true>(tx, ty, tz, B.ntrg(), sx, sy, sz, f.data(), A.nsrc(), u.data(), sc);
          else p2p_mixed<Kernel, false>(tx, ty, tz, B.ntrg(), sx, sy, sz, f.data(), A.nsrc(), u.data(), sc);
        } else if (fast_rsqrt_) {
          if (self) p2p_multi<Kernel, 1, true>(nd, tx, ty, tz, B.ntrg(), sx, sy, sz, f.data(), A.nsrc(), u.data(), sc);
          else p2p_multi<Kernel, 1, false>(nd, tx, ty, tz, B.ntrg(), sx, sy, sz, f.data(), A.nsrc(), u.data(), sc);
        } else {
          if (self) p2p_multi<Kernel, 2, true>(nd, tx, ty, tz, B.ntrg(), sx, sy, sz, f.data(), A.nsrc(), u.data(), sc);
          else p2p_multi<Kernel, 2, false>(nd, tx, ty, tz, B.ntrg(), sx, sy, sz, f.data(), A.nsrc(), u.data(), sc);
        }
      };
      for (std::size_t j = T.U.begin[b]; j < T.U.begin[b + 1]; ++j) direct_from(T.nodes[T.U.item[j]]);
      for (std::size_t j = T.W.begin[b]; j < T.W.begin[b + 1]; ++j) {
        const int d = T.W.item[j];
        const Node& D = T.nodes[d];
        if (D.nsrc() <= static_cast<std::size_t>(n)) { direct_from(D); continue; }
        double c[3];
        T.center(d, c);
        op.surface().place(c, kRadInner * Tree::half_width(D.level), px.data(), py.data(), pz.data());
        for (int e = 0; e < nd; ++e)
          detail::true_equivalent_density<Up>(ue_.data() + (static_cast<std::size_t>(d) * nd + e) * ldu, n,
                                              Tree::half_width(D.level), scaled.empty() ? nullptr : scaled.data() + e * ldu,
                                              f.data() + e * SU);
        p2p_multi<Up, 2, false>(nd, tx, ty, tz, B.ntrg(), px.data(), py.data(), pz.data(), f.data(), n,
                                u.data(), Up::scale());
      }
      for (int a = b; a >= 0; a = T.nodes[a].parent)
        if (x_direct_[a])
          for (std::size_t j = T.X.begin[a]; j < T.X.begin[a + 1]; ++j) direct_from(T.nodes[T.X.item[j]]);
    }
  }
  t_.p2p += detail::wall_now() - t;
}

template <class Kernel>
void Fmm<Kernel>::local_to_targets() {
  constexpr int SDn = Down::src_dim, TD = Kernel::trg_dim;
  const Operators<Kernel>& op = *ops_;
  const int n = op.nsurf(), nd = nd_;
  const std::size_t ldd = SDn * n;
  const Tree& T = tree_;
  const double t = detail::wall_now();
  const auto& leaves = T.leaves;
#pragma omp parallel num_threads(threads_)
  {
    std::vector<double> px(n), py(n), pz(n);
    std::vector<const double*> f(SDn * nd);
    std::vector<double> scaled(has_degree_shift<Down>() ? ldd * nd : 0);
    std::vector<double*> u(TD * nd);
#pragma omp for schedule(dynamic, 2)
    for (long li = 0; li < static_cast<long>(leaves.size()); ++li) {
      const int b = leaves[li];
      const Node& B = T.nodes[b];
      if (B.ntrg() == 0 || B.level < 2) continue;
      double c[3];
      T.center(b, c);
      op.surface().place(c, kRadOuter * Tree::half_width(B.level), px.data(), py.data(), pz.data());
      for (int e = 0; e < nd; ++e)
        detail::true_equivalent_density<Down>(de_.data() + (static_cast<std::size_t>(b) * nd + e) * ldd, n,
                                              Tree::half_width(B.level), scaled.empty() ? nullptr : scaled.data() + e * ldd,
                                              f.data() + e * SDn);
      for (int k = 0; k < TD * nd; ++k) u[k] = u_.data() + k * n_trg_ + B.tb;
      p2p_multi<Down, 2, false>(nd, T.tx.data() + B.tb, T.ty.data() + B.tb, T.tz.data() + B.tb, B.ntrg(),
                                px.data(), py.data(), pz.data(), f.data(), n, u.data(), Down::scale());
    }
  }
  t_.l2p += detail::wall_now() - t;
}

}  // namespace capsflow::fmm
