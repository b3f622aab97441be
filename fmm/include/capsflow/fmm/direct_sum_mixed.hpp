#pragma once
// capsflow::fmm::direct_sum_mixed<Kernel> — a kernel's direct sum (conventions of direct_sum.hpp;
// output OVERWRITTEN) with every pair in single precision and the sums in double;
// stokeslet_direct_sum_mixed is the Stokeslet's (the single layer's far field).
//
// The pairs are p2p_mixed's (single-precision pairs, double sums; p2p_mixed.hpp) in direct_sum's
// frame (target blocks of 128, source tiles of 4 096, each tile shifted to its block's origin).
// Measured (Stokeslet): on capsule meshes max error 4e-7 of max |u| and 1e-7 in L2; for random
// forces at random points on a sphere 3.6e-7 in L2 (tests/fmm/test_kernels.cpp checks
// close-approach clouds too, and the stresslet); 1.3x the double pairs with AVX-512, 2.0x with
// AVX2 (perf/fmm/RESULTS.md, "Single-precision pairs"). Sources must not coincide with targets (no
// r = 0 test). Without a single-precision vector type: direct_sum with one Newton step.
#include <cstddef>

#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/p2p_mixed.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow::fmm {

/// True when direct_sum_mixed really sums single-precision pairs (AVX-512 or AVX2 builds).
inline constexpr bool kMixedPrecisionDirectSum = simd::kHasSinglePrecisionPairs;

template <class Kernel>
void direct_sum_mixed(const double* src, std::size_t n_src, const double* density, const double* trg, std::size_t n_trg,
                      double* out, int threads = 0) {
  if constexpr (simd::kHasSinglePrecisionPairs)
    detail::direct_sum_by_blocks<Kernel>(src, n_src, density, trg, n_trg, out, threads,
                                         [](auto... a) { p2p_mixed<Kernel, false>(a...); });
  else
    direct_sum<Kernel, 1, false>(src, n_src, density, trg, n_trg, out, threads);
}

inline void stokeslet_direct_sum_mixed(const double* src, std::size_t n_src, const double* density, const double* trg,
                                       std::size_t n_trg, double* out, int threads = 0) {
  direct_sum_mixed<Stokeslet>(src, n_src, density, trg, n_trg, out, threads);
}

}  // namespace capsflow::fmm
