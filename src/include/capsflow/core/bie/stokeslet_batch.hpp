#pragma once
// A batch of Stokeslet terms seen from one target: Σ_j G(r_j) f_j with the pair formula of
// fmm::Stokeslet (unscaled: the caller multiplies by fmm::Stokeslet::scale()).
//
// The local (near-field) correction of the single layer at a node is a few hundred such terms:
// Duffy points of the touching elements, 7-point rules of the near ring, 3-point rules of the
// band, minus the far-field terms of the same elements. Gathering them first and summing them in one
// structure-of-arrays loop lets the compiler vectorise across terms (the far-field kernel
// vectorises across targets, which does not help a single target).
#include <cmath>
#include <vector>

#include "capsflow/core/types.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow {

class alignas(64) StokesletBatch {  // one per thread: own cache lines (push writes n_)
 public:
  void clear() { n_ = 0; }
  void push(double rx, double ry, double rz, double fx, double fy, double fz) {
    if (n_ == rx_.size()) grow();
    rx_[n_] = rx, ry_[n_] = ry, rz_[n_] = rz;
    fx_[n_] = fx, fy_[n_] = fy, fz_[n_] = fz;
    ++n_;
  }
  void push(const Vec3& r, const Vec3& f) { push(r.x(), r.y(), r.z(), f.x(), f.y(), f.z()); }
  std::size_t size() const { return n_; }
  // Σ_j G(r_j) f_j, with capsflow::fmm's SIMD vector type (rsqrt + 2 Newton steps: full double
  // accuracy). Lanes past the end load r = f = 0, which the masked rsqrt turns into 0.
  Vec3 sum() const {
    using V = fmm::simd::VecD;
    constexpr int W = V::width;
    V u[3] = {V(0.0), V(0.0), V(0.0)};
    for (std::size_t j = 0; j < n_; j += W) {
      const int m = static_cast<int>(n_ - j < static_cast<std::size_t>(W) ? n_ - j : W);
      const V r[3] = {V::load_partial(&rx_[j], m), V::load_partial(&ry_[j], m), V::load_partial(&rz_[j], m)};
      const V f[3] = {V::load_partial(&fx_[j], m), V::load_partial(&fy_[j], m), V::load_partial(&fz_[j], m)};
      const V r2 = fmm::simd::fma(r[0], r[0], fmm::simd::fma(r[1], r[1], r[2] * r[2]));
      fmm::Stokeslet::eval(u, r, fmm::simd::rsqrt<2, true>(r2), f);  // masked: padded lanes (r2 = 0) give 0
    }
    double bx[W], by[W], bz[W];
    u[0].store(bx), u[1].store(by), u[2].store(bz);
    Vec3 out = Vec3::Zero();
    for (int k = 0; k < W; ++k) out += Vec3(bx[k], by[k], bz[k]);
    return out;
  }

 private:
  void grow() {
    const std::size_t m = rx_.empty() ? 512 : 2 * rx_.size();
    for (auto* v : {&rx_, &ry_, &rz_, &fx_, &fy_, &fz_}) v->resize(m);
  }
  std::size_t n_ = 0;
  std::vector<double> rx_, ry_, rz_, fx_, fy_, fz_;
};

}  // namespace capsflow
