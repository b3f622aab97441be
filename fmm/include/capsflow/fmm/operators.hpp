#pragma once
// capsflow::fmm::Operators<Kernel> — the translation operators of the KIFMM, one object per
// (kernel, order). Lifetime: built once, loaded from / saved to the disk cache.
// They are those of the kernel's equivalent kernels (equivalent.hpp): E_up for uc2ue, m2m and the
// M2L spectra, E_down for dc2de and l2l (both the kernel itself for the Stokeslet).
//
// Scale invariance (kernel homogeneous of degree h): everything is built for a reference box of
// half-width 1. Vectors are component-major: entry (c, k) of a surface vector is at c*n + k.
//   uc2ue : pseudo-inverse of K(UC@2.95 <- UE@1.05)            (src_dim·n × trg_dim·n); for a
//           kernel without net force (equivalent.hpp) followed by the removal of the densities'
//           net force (the mean of each force component), folded into its factor vs
//   dc2de : pseudo-inverse of K(DC@1.05 <- DE@2.95)
//           both stored and applied as two SVD factors (PinvFactors: why)
//   m2m[o]: K(parent UC@2.95 <- child-o UE)   (child half-width 1/2, centre at ±1/2) — the
//           parent UE is then uc2ue · Σ_o m2m[o]·UE_child (level-independent); the column of a
//           density component with its own degree (equivalent.hpp) carries 2^{degree_shift}.
//   l2l[o]: 0.5^{-h} K(child-o DC <- parent DE@2.95) — added to the child's reference check
//           potential, which dc2de then turns into the child's DE.
// A level-l box of half-width r has K_l = r^h K_ref, so P2M and P2L multiply check potentials
// computed in true (normalised) coordinates by r^{-h} before applying uc2ue / dc2de.
// Regularisation: singular values below pinv_rel_tol(p)·s_max (1e-10, 1e-11 for p >= 11) are
// dropped (docs/fmm.md §3.2: truncating at machine epsilon ruins the Stokeslet at p >= 10
// because of its exact null direction).
#include <omp.h>

#include <Eigen/Dense>
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include "capsflow/fmm/cache.hpp"
#include "capsflow/fmm/equivalent.hpp"
#include "capsflow/fmm/m2l_fft.hpp"
#include "capsflow/fmm/surface.hpp"

namespace capsflow::fmm {

/// Relative singular-value cut of the check -> equivalent pseudo-inverses, per order. Measured
/// (perf/fmm/RESULTS.md, "Accuracy floor"): with factored pseudo-inverses the FMM error at N = 1e4
/// is 1.1e-8 / 1.3e-9 / 1.4e-10 (p = 10 / 12 / 14) at 1e-10, and 1.7e-8 / 6.4e-10 / 6.3e-11 at
/// 1e-11: a deeper cut pays once the surface resolves the field (p >= 11), but at p <= 10 it only
/// adds ill-conditioned singular triplets. 4·ε (PVFMM's default) ruins the Stokeslet at p >= 10
/// (docs/fmm.md §3.2).
inline double pinv_rel_tol(int p) { return p <= 10 ? 1e-10 : 1e-11; }


/// Dense kernel matrix K (trg_dim·nt × src_dim·ns), component-major, scale included. For kernels
/// linear in the density (the equivalent kernels); the stresslet, bilinear in (f, n), has none.
template <class Kernel>
Eigen::MatrixXd kernel_matrix(const double* tx, const double* ty, const double* tz, int nt,
                              const double* sx, const double* sy, const double* sz, int ns) {
  constexpr int SD = Kernel::src_dim, TD = Kernel::trg_dim;
  Eigen::MatrixXd K(TD * nt, SD * ns);
  for (int j = 0; j < ns; ++j)
    for (int i = 0; i < nt; ++i) {
      const double r[3] = {tx[i] - sx[j], ty[i] - sy[j], tz[i] - sz[j]};
      const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
      const double ri = r2 > 0 ? 1.0 / std::sqrt(r2) : 0.0;
      for (int b = 0; b < SD; ++b) {
        double f[SD] = {};
        f[b] = 1.0;
        double u[TD] = {};
        Kernel::eval(u, r, ri, f);
        for (int a = 0; a < TD; ++a) K(a * nt + i, b * ns + j) = Kernel::scale() * u[a];
      }
    }
  return K;
}

/// Truncated-SVD pseudo-inverse K⁺ = V S⁺ Uᵀ, dropping singular values below rel·s_max, kept
/// as two factors: vs = V_r S_r⁻¹ (cols × r) and ut = U_rᵀ (r × rows), applied as vs·(ut·c).
/// Why factored: the product V S⁺ Uᵀ has entries of size 1/s_min ≈ 1e10/s_max, and any rounding
/// in forming or applying it (relative ε to those entries) lands in EVERY direction of the
/// result, including the dominant singular directions that the next translation does not damp:
/// ~ε·1e10 relative = the 1.5e-8–3e-8 accuracy floor measured with the product (RESULTS.md).
/// Applied as two factors, the rounding of ut·c is ε·|c| per singular coordinate and is then
/// amplified only along the direction v_k whose field the next kernel damps by the same s_k.
struct PinvFactors {
  Eigen::MatrixXd vs, ut;
  Eigen::MatrixXd product() const { return vs * ut; }  ///< for tests and small problems only
};

inline PinvFactors regularised_pinv_factors(const Eigen::MatrixXd& K, double rel) {
  Eigen::BDCSVD<Eigen::MatrixXd> svd(K, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const auto& s = svd.singularValues();
  const double cut = rel * (s.size() ? s(0) : 0.0);
  int r = 0;
  while (r < s.size() && s(r) > cut) ++r;
  PinvFactors f;
  f.vs = svd.matrixV().leftCols(r) * s.head(r).cwiseInverse().asDiagonal();
  f.ut = svd.matrixU().leftCols(r).transpose();
  return f;
}

template <class Kernel>
class Operators {
 public:
  using Up = typename UpwardEquivalentOf<Kernel>::type;
  using Down = typename DownwardEquivalentOf<Kernel>::type;
  static_assert(Up::trg_dim == Kernel::trg_dim && Down::trg_dim == Kernel::trg_dim,
                "equivalent kernels must produce the kernel's target components");
  static_assert(Up::homogeneity == Down::homogeneity, "check potentials share one reference scaling");

  /// Build or load the operators of order p. cache_dir "" => resolve_cache_dir("") (env vars);
  /// if no directory can be resolved or written, the operators are built and not saved.
  Operators(int p, const std::string& cache_dir) : surf_(p), m2l_(surf_) {
    const int n = surf_.n;
    const std::string dir = resolve_cache_dir(cache_dir);
    char key[256];
    std::snprintf(key, sizeof key, "kernel=%s order=%d nsurf=%d src=%d trg=%d rin=%.17g rout=%.17g reg=%.3g prec=f64",
                  Kernel::name, p, n, Kernel::src_dim, Kernel::trg_dim, kRadInner, kRadOuter, pinv_rel_tol(p));
    key_ = std::string(key) + " pinv=factored";
    if constexpr (has_own_equivalents<Kernel>)
      key_ += std::string(" up=") + Up::name + " down=" + Down::name;
    if constexpr (NetForceFree<Kernel>::value) key_ += " up_net_force=0";
    if (!dir.empty()) path_ = dir + "/" + Kernel::name + "_p" + std::to_string(p) + "_f64.bin";
    std::vector<Eigen::MatrixXd> mats;
    const int TD = Kernel::trg_dim;
    auto factor_ok = [&](const Eigen::MatrixXd& vs, const Eigen::MatrixXd& ut, int SD) {
      return vs.rows() == SD * n && ut.cols() == TD * n && vs.cols() == ut.rows() && vs.cols() >= 1 &&
             vs.cols() <= std::min(SD, TD) * n;
    };
    if (!path_.empty() && load_operator_cache(path_, key_, mats) && mats.size() == 4 &&
        factor_ok(mats[0], mats[1], Up::src_dim) && factor_ok(mats[2], mats[3], Down::src_dim)) {
      uc2ue_.vs = std::move(mats[0]);
      uc2ue_.ut = std::move(mats[1]);
      dc2de_.vs = std::move(mats[2]);
      dc2de_.ut = std::move(mats[3]);
      loaded_ = true;
    } else {
      build_pinvs();
      if (!path_.empty())
        saved_ = save_operator_cache(path_, key_, {uc2ue_.vs, uc2ue_.ut, dc2de_.vs, dc2de_.ut});
    }
    build_translations();
    m2l_.template precompute<Up>();
  }

  int order() const { return surf_.p; }
  int nsurf() const { return surf_.n; }
  const Surface& surface() const { return surf_; }
  /// check -> equivalent pseudo-inverses, as factors (apply vs·(ut·c), never the product)
  const PinvFactors& uc2ue() const { return uc2ue_; }
  const PinvFactors& dc2de() const { return dc2de_; }
  const Eigen::MatrixXd& m2m(int o) const { return m2m_[o]; }
  const Eigen::MatrixXd& l2l(int o) const { return l2l_[o]; }
  const M2lFft& m2l() const { return m2l_; }
  bool loaded_from_cache() const { return loaded_; }
  bool saved_to_cache() const { return saved_; }
  const std::string& cache_file() const { return path_; }

 private:
  std::vector<double> scaled(const std::vector<double>& v, double a, double shift) const {
    std::vector<double> o(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) o[i] = shift + a * v[i];
    return o;
  }
  template <class K>
  Eigen::MatrixXd kmat(double rt, const double ct[3], double rs, const double cs[3]) const {
    const auto tx = scaled(surf_.x, rt, ct[0]), ty = scaled(surf_.y, rt, ct[1]), tz = scaled(surf_.z, rt, ct[2]);
    const auto sx = scaled(surf_.x, rs, cs[0]), sy = scaled(surf_.y, rs, cs[1]), sz = scaled(surf_.z, rs, cs[2]);
    return kernel_matrix<K>(tx.data(), ty.data(), tz.data(), surf_.n, sx.data(), sy.data(), sz.data(), surf_.n);
  }
  void build_pinvs() {
    const double c0[3] = {0, 0, 0};
    const double rel = pinv_rel_tol(surf_.p);
    uc2ue_ = regularised_pinv_factors(kmat<Up>(kRadOuter, c0, kRadInner, c0), rel);
    if constexpr (NetForceFree<Kernel>::value) {
      // (I − mean) on the rows of the force components: every upward density has zero net force
      // (docs/fmm.md §3.10: without it the stresslet's error grows by 2 per level of a deep tree)
      static_assert(Up::src_dim >= 3, "the upward density's components 0-2 are Stokeslet forces");
      const int n = surf_.n;
      for (int a = 0; a < 3; ++a) {
        const Eigen::RowVectorXd mean = uc2ue_.vs.middleRows(a * n, n).colwise().mean();
        uc2ue_.vs.middleRows(a * n, n).rowwise() -= mean;
      }
    }
    dc2de_ = regularised_pinv_factors(kmat<Down>(kRadInner, c0, kRadOuter, c0), rel);
  }
  void build_translations() {
    const double c0[3] = {0, 0, 0};
    const double child_scale = std::pow(0.5, -Down::homogeneity);
    const int n = surf_.n;
    // 16 kernel matrices of up to 1 500 × 2 000 entries at p = 10 (most of the operators' build
    // time once the pseudo-inverses come from the cache): one per task.
#pragma omp parallel for schedule(dynamic, 1)
    for (int task = 0; task < 16; ++task) {
      const int o = task % 8;
      const double cc[3] = {(o & 1) ? 0.5 : -0.5, (o & 2) ? 0.5 : -0.5, (o & 4) ? 0.5 : -0.5};
      if (task < 8) {
        m2m_[o] = kmat<Up>(kRadOuter, c0, 0.5 * kRadInner, cc);
        // the child stores a shifted component scaled by its own half-width, the parent's check by
        // the parent's: a factor (ρ_parent/ρ_child)^shift = 2^shift (docs/fmm.md §3.10)
        if constexpr (has_degree_shift<Up>())
          for (int b = 0; b < Up::src_dim; ++b)
            if (degree_shift<Up>(b) != 0) m2m_[o].middleCols(b * n, n) *= std::pow(2.0, degree_shift<Up>(b));
      } else {
        l2l_[o] = kmat<Down>(0.5 * kRadInner, cc, kRadOuter, c0);
        l2l_[o] *= child_scale;
      }
    }
  }

  Surface surf_;
  M2lFft m2l_;
  PinvFactors uc2ue_, dc2de_;
  Eigen::MatrixXd m2m_[8], l2l_[8];
  std::string key_, path_;
  bool loaded_ = false, saved_ = false;
};

}  // namespace capsflow::fmm
