#pragma once
// The FMM-against-direct-summation check shared by the fmm tests: operators built once per
// (kernel, order) for a test binary, and the relative L2 error of one FMM evaluation against
// direct_sum for random densities. Needs CAPSFLOW_FMM_TEST_CACHE (tests/fmm/CMakeLists.txt).
#include <map>
#include <memory>
#include <vector>

#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/fmm.hpp"
#include "points.hpp"

namespace capsflow::fmm::testing {

// Operators are expensive to build: one per (kernel, order) for the whole test binary.
template <class Kernel>
std::shared_ptr<const Operators<Kernel>> ops_for(int p) {
  static std::map<int, std::shared_ptr<const Operators<Kernel>>> cache;
  auto& o = cache[p];
  if (!o) o = std::make_shared<const Operators<Kernel>>(p, CAPSFLOW_FMM_TEST_CACHE);
  return o;
}

/// Relative L2 error over all targets of the FMM at the kernel's calibrated order for `tol`
/// (leaf = points per leaf, 0 = default) against direct_sum; *out receives the FMM result;
/// single_pairs sets FmmOptions::single_precision_pairs.
template <class Kernel>
double fmm_error(const std::vector<double>& s, const std::vector<double>& t, double tol, int leaf,
                 std::vector<double>* out = nullptr, bool single_pairs = false) {
  constexpr int SD = Kernel::src_dim, TD = Kernel::trg_dim;
  const std::size_t ns = s.size() / 3, nt = t.size() / 3;
  const auto f = random_density(SD * ns, 99);
  FmmOptions o;
  o.tolerance = tol;
  o.leaf_size = leaf;
  o.single_precision_pairs = single_pairs;
  Fmm<Kernel> fmm(o, ops_for<Kernel>(order_for_tolerance<Kernel>(tol)));
  fmm.setup(s.data(), ns, t.data(), nt);
  std::vector<double> u(TD * nt, 7.0), ref(TD * nt);
  fmm.evaluate(f.data(), u.data());
  direct_sum<Kernel>(s.data(), ns, f.data(), t.data(), nt, ref.data());
  if (out) *out = u;
  return rel_l2(u, ref);
}

}  // namespace capsflow::fmm::testing
