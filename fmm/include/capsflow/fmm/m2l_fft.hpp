#pragma once
// capsflow::fmm::M2lFft — FFT-accelerated M2L (multipole-to-local) for the KIFMM.
//
// The UE surface of a source box and the DC surface of a V-list target box (both at 1.05·r) lie
// on lattices with the same spacing h = 2·1.05·r/(p−1), so for centres c_T − c_S = D
//   check_j = Σ_i K(D + h(j − i)) m_i,
// a discrete convolution on an m^3 grid, m = grid_size(p) >= 2p (circular, no aliasing since
// |j − i| ≤ p − 1 < m/2).
// Precomputed once per order: the r2c spectra of K sampled at D + h·n for the 316 V-list offsets
// (reference box, half-width 1; the 1/(2p)^3 of the inverse FFT is folded in). Because the
// kernel is homogeneous, the same spectra serve every level when M2L writes reference-scaled
// check potentials (see operators.hpp).
// Spectra are stored split (re/im) in chunks of kChunk frequencies so that the Hadamard products
// are plain SIMD loops and one chunk of all 316 kernels stays in cache while all target boxes
// of a level stream through it.
// FFTW plans are made once (serially, under a process-wide lock: the FFTW planner is not
// thread-safe) and executed from threads with the new-array interface on fftw_malloc'ed buffers.
#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <mutex>
#include <vector>

#include "capsflow/fmm/simd.hpp"
#include "capsflow/fmm/surface.hpp"
#include "capsflow/fmm/tree.hpp"

namespace capsflow::fmm {

inline std::mutex& fftw_planner_mutex() {
  static std::mutex m;
  return m;
}

/// RAII fftw_malloc buffer
template <class T>
struct FftwBuffer {
  T* p = nullptr;
  explicit FftwBuffer(std::size_t n = 0) { if (n) p = static_cast<T*>(fftw_malloc(sizeof(T) * n)); }
  ~FftwBuffer() { if (p) fftw_free(p); }
  FftwBuffer(const FftwBuffer&) = delete;
  FftwBuffer& operator=(const FftwBuffer&) = delete;
};

class M2lFft {
 public:
  static constexpr int kChunk = 8;  // frequencies per block: one AVX-512 vector

  explicit M2lFft(const Surface& s) : surf_(s) {}
  ~M2lFft() {
    std::lock_guard<std::mutex> lk(fftw_planner_mutex());
    if (fwd_) fftw_destroy_plan(fwd_);
    if (bwd_) fftw_destroy_plan(bwd_);
  }
  M2lFft(const M2lFft&) = delete;
  M2lFft& operator=(const M2lFft&) = delete;

  int grid() const { return m_; }
  /// FFT grid edge: any m >= 2p − 1 avoids aliasing; 2p except where FFTW is slow (measured:
  /// 18 is 2.5x slower than 20 on this machine), then the next even size.
  static int grid_size(int p) {
    int m = 2 * p;
    if (m == 18 || m == 22 || m == 26 || m == 34 || m == 38) m += 2;
    return m;
  }
  std::size_t nreal() const { return n3_; }
  std::size_t nfreq() const { return nf_; }
  int nchunk() const { return nchunk_; }
  std::size_t src_spec_size() const { return static_cast<std::size_t>(nchunk_) * sd_ * 2 * kChunk; }
  std::size_t trg_spec_size() const { return static_cast<std::size_t>(nchunk_) * td_ * 2 * kChunk; }
  /// kernel spectrum block for chunk c and V offset o: [td*sd][re,im][kChunk]
  const double* kernel(int c, int o) const {
    return kspec_.get() + (static_cast<std::size_t>(c) * kNumVOffsets + o) * (td_ * sd_ * 2 * kChunk);
  }
  int src_dim() const { return sd_; }
  int trg_dim() const { return td_; }

  template <class Kernel>
  void precompute() {
    sd_ = Kernel::src_dim;
    td_ = Kernel::trg_dim;
    const int p = surf_.p;
    m_ = grid_size(p);
    gidx_.resize(surf_.n);
    for (int k = 0; k < surf_.n; ++k)
      gidx_[k] = (surf_.lattice[3 * k] * m_ + surf_.lattice[3 * k + 1]) * m_ + surf_.lattice[3 * k + 2];
    n3_ = static_cast<std::size_t>(m_) * m_ * m_;
    const int mh = m_ / 2 + 1;
    nf_ = static_cast<std::size_t>(m_) * m_ * mh;
    nchunk_ = static_cast<int>((nf_ + kChunk - 1) / kChunk);
    FftwBuffer<double> rin(n3_ * (sd_ > td_ ? sd_ : td_));
    FftwBuffer<fftw_complex> cout(nf_ * (sd_ > td_ ? sd_ : td_));
    fftw_plan single;
    {
      std::lock_guard<std::mutex> lk(fftw_planner_mutex());
      const int dims[3] = {m_, m_, m_};
      fwd_ = fftw_plan_many_dft_r2c(3, dims, sd_, rin.p, nullptr, 1, static_cast<int>(n3_), cout.p,
                                    nullptr, 1, static_cast<int>(nf_), FFTW_MEASURE);
      bwd_ = fftw_plan_many_dft_c2r(3, dims, td_, cout.p, nullptr, 1, static_cast<int>(nf_), rin.p,
                                    nullptr, 1, static_cast<int>(n3_), FFTW_MEASURE);
      single = fftw_plan_dft_r2c_3d(m_, m_, m_, rin.p, cout.p, FFTW_ESTIMATE);
    }
    // Every frequency below nf_ of every V offset is written below (the spectra run to hundreds of
    // MB at p ≥ 9: no zero pass first, and the threads' first writes spread the page faults);
    // only the last chunk's padding frequencies are zeroed here.
    const std::size_t block = static_cast<std::size_t>(td_) * sd_ * 2 * kChunk;
    kspec_.reset(new double[static_cast<std::size_t>(nchunk_) * kNumVOffsets * block]);
    for (int o = 0; o < kNumVOffsets; ++o)
      std::fill_n(kspec_.get() + (static_cast<std::size_t>(nchunk_ - 1) * kNumVOffsets + o) * block, block, 0.0);
    const double h = 2.0 * kRadInner / (p - 1);
    const double norm = 1.0 / static_cast<double>(n3_);
#pragma omp parallel
    {
      // Every offset samples the same grid points: the rest of the grid is zeroed once.
      FftwBuffer<double> g(n3_ * td_ * sd_);
      for (std::size_t i = 0; i < n3_ * td_ * sd_; ++i) g.p[i] = 0.0;
      FftwBuffer<fftw_complex> gc(nf_);
#pragma omp for schedule(dynamic, 1)
      for (int o = 0; o < 343; ++o) {
        const int dx = o % 7 - 3, dy = (o / 7) % 7 - 3, dz = o / 49 - 3;
        const int oi = v_offset_index(dx, dy, dz);
        if (oi < 0) continue;
        // sample K(D + h n), D = 2d (centres of half-width-1 boxes), n in [-(p-1), p-1]^3
        for (int nx = -(p - 1); nx <= p - 1; ++nx)
          for (int ny = -(p - 1); ny <= p - 1; ++ny)
            for (int nz = -(p - 1); nz <= p - 1; ++nz) {
              const double r[3] = {2.0 * dx + h * nx, 2.0 * dy + h * ny, 2.0 * dz + h * nz};
              const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
              const double ri = 1.0 / std::sqrt(r2);
              const std::size_t idx = (static_cast<std::size_t>((nx + m_) % m_) * m_ + (ny + m_) % m_) * m_ + (nz + m_) % m_;
              for (int b = 0; b < sd_; ++b) {
                double f[Kernel::src_dim] = {};
                f[b] = 1.0;
                double u[Kernel::trg_dim] = {};
                Kernel::eval(u, r, ri, f);
                for (int a = 0; a < td_; ++a) g.p[(a * sd_ + b) * n3_ + idx] = Kernel::scale() * u[a] * norm;
              }
            }
        for (int ab = 0; ab < td_ * sd_; ++ab) {
          fftw_execute_dft_r2c(single, g.p + ab * n3_, gc.p);
          for (std::size_t f = 0; f < nf_; ++f) {
            const std::size_t c = f / kChunk, q = f % kChunk;
            double* blk = kspec_.get() + (c * kNumVOffsets + oi) * (td_ * sd_ * 2 * kChunk) + ab * 2 * kChunk;
            blk[q] = gc.p[f][0];
            blk[kChunk + q] = gc.p[f][1];
          }
        }
      }
    }
    std::lock_guard<std::mutex> lk(fftw_planner_mutex());
    fftw_destroy_plan(single);
  }

  static constexpr int kBatch = 8;  // boxes transformed together (contiguous chunk-major writes)

  /// Per-thread scratch for forward/backward transforms.
  struct Work {
    FftwBuffer<double> real;
    FftwBuffer<fftw_complex> cplx;
    explicit Work(const M2lFft& f)
        : real(f.n3_ * (f.sd_ > f.td_ ? f.sd_ : f.td_)),
          cplx(f.nf_ * (f.sd_ > f.td_ ? f.sd_ : f.td_) * kBatch) {
      for (std::size_t i = 0; i < f.n3_ * (f.sd_ > f.td_ ? f.sd_ : f.td_); ++i) real.p[i] = 0.0;
    }
  };

  /// UE densities (component-major, src_dim·n each) of boxes j0 .. j0+g−1 (g <= kBatch, of
  /// count) -> split spectra, stored chunk-major: block (c, j, b) at
  /// spec + ((c*count + j)*SD + b)*2*kChunk, so the g boxes of one chunk are contiguous.
  void forward(const double* const* ue, int g, double* spec, std::size_t j0, std::size_t count,
               Work& w) const {
    // Only the surface positions of the real grid are ever written; the rest stays zero from
    // Work's construction (r2c out of place preserves its input).
    const int n = surf_.n;
    for (int i = 0; i < g; ++i) {
      for (int b = 0; b < sd_; ++b)
        for (int k = 0; k < n; ++k) w.real.p[b * n3_ + gidx_[k]] = ue[i][b * n + k];
      fftw_execute_dft_r2c(fwd_, w.real.p, w.cplx.p + static_cast<std::size_t>(i) * sd_ * nf_);
    }
    for (int c = 0; c < nchunk_; ++c) {
      double* blk = spec + (static_cast<std::size_t>(c) * count + j0) * sd_ * 2 * kChunk;
      const std::size_t f0 = static_cast<std::size_t>(c) * kChunk;
      const int nq = static_cast<int>(std::min<std::size_t>(kChunk, nf_ - f0));
      for (int i = 0; i < g; ++i)
        for (int b = 0; b < sd_; ++b, blk += 2 * kChunk) {
          const fftw_complex* in = w.cplx.p + (static_cast<std::size_t>(i) * sd_ + b) * nf_ + f0;
          for (int q = 0; q < nq; ++q) { blk[q] = in[q][0]; blk[kChunk + q] = in[q][1]; }
          for (int q = nq; q < kChunk; ++q) { blk[q] = 0.0; blk[kChunk + q] = 0.0; }
        }
    }
  }

  /// chunk-major target spectra of boxes j0 .. j0+g−1 (of count) -> ADD their DC check
  /// potentials (component-major, trg_dim·n each) to check[i].
  void backward(const double* spec, std::size_t j0, int g, std::size_t count, double* const* check,
                Work& w) const {
    const int n = surf_.n;
    for (int c = 0; c < nchunk_; ++c) {
      const double* blk = spec + (static_cast<std::size_t>(c) * count + j0) * td_ * 2 * kChunk;
      const std::size_t f0 = static_cast<std::size_t>(c) * kChunk;
      const int nq = static_cast<int>(std::min<std::size_t>(kChunk, nf_ - f0));
      for (int i = 0; i < g; ++i)
        for (int a = 0; a < td_; ++a, blk += 2 * kChunk) {
          fftw_complex* out = w.cplx.p + (static_cast<std::size_t>(i) * td_ + a) * nf_ + f0;
          for (int q = 0; q < nq; ++q) { out[q][0] = blk[q]; out[q][1] = blk[kChunk + q]; }
        }
    }
    for (int i = 0; i < g; ++i) {
      fftw_execute_dft_c2r(bwd_, w.cplx.p + static_cast<std::size_t>(i) * td_ * nf_, w.real.p);
      for (int a = 0; a < td_; ++a)
        for (int k = 0; k < n; ++k) check[i][a * n + k] += w.real.p[a * n3_ + gidx_[k]];
    }
  }

  /// For one frequency chunk c and one V offset o: for every (target t, source s) in `pairs`,
  ///   acc_t += K(o) ⊙ src_s   (split complex; src_chunk / trg_chunk = box-major spectra of
  ///                            chunk c; pairs = t0,s0,t1,s1,...).
  /// The kernel block of (c, o) stays in vector registers while the pairs stream through.
  template <int TD, int SD>
  void hadamard_pairs(int c, int o, const int* pairs, std::size_t count, const double* src_chunk,
                      double* trg_chunk) const {
    using V = simd::VecD;
    constexpr int CH = kChunk, W = V::width;
    const double* k = kernel(c, o);
    for (int q0 = 0; q0 < CH; q0 += W) {
      V kr[TD * SD], ki[TD * SD];
      for (int ab = 0; ab < TD * SD; ++ab) {
        kr[ab] = V::load(k + ab * 2 * CH + q0);
        ki[ab] = V::load(k + ab * 2 * CH + CH + q0);
      }
      for (std::size_t p = 0; p < count; ++p) {
        const double* u = src_chunk + static_cast<std::size_t>(pairs[2 * p + 1]) * SD * 2 * CH + q0;
        double* acc = trg_chunk + static_cast<std::size_t>(pairs[2 * p]) * TD * 2 * CH + q0;
        V ur[SD], ui[SD];
        for (int b = 0; b < SD; ++b) { ur[b] = V::load(u + b * 2 * CH); ui[b] = V::load(u + b * 2 * CH + CH); }
        for (int a = 0; a < TD; ++a) {
          V ar = V::load(acc + a * 2 * CH), ai = V::load(acc + a * 2 * CH + CH);
          for (int b = 0; b < SD; ++b) {
            ar = simd::fma(kr[a * SD + b], ur[b], ar);
            ar = simd::fnma(ki[a * SD + b], ui[b], ar);
            ai = simd::fma(kr[a * SD + b], ui[b], ai);
            ai = simd::fma(ki[a * SD + b], ur[b], ai);
          }
          ar.store(acc + a * 2 * CH);
          ai.store(acc + a * 2 * CH + CH);
        }
      }
    }
  }

 private:
  const Surface& surf_;
  int sd_ = 1, td_ = 1, m_ = 0, nchunk_ = 0;
  std::size_t n3_ = 0, nf_ = 0;
  fftw_plan fwd_ = nullptr, bwd_ = nullptr;
  std::unique_ptr<double[]> kspec_;  // uninitialised on allocation (see precompute)
  std::vector<int> gidx_;  // surface point -> index in the m^3 grid
};

}  // namespace capsflow::fmm
