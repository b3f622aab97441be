#include <gtest/gtest.h>
#include <cstdio>
#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/fmm.hpp"
#include "capsflow/fmm/stokeslet.hpp"
#include "capsflow/fmm/laplace.hpp"
#include "points.hpp"
using namespace capsflow::fmm;
using namespace capsflow::fmm::testing;
TEST(Quick, Run) {
  for (int p : {4, 6, 8, 10}) {
    FmmOptions o; o.order = p; o.leaf_size = 100; o.cache_dir = CAPSFLOW_FMM_TEST_CACHE;
    double t0 = omp_get_wtime();
    Fmm<Stokeslet> fmm(o);
    double t1 = omp_get_wtime();
    auto x = make_points("sphere", 20000, 1);
    auto f = random_density(3 * 20000, 2);
    fmm.setup(x.data(), 20000, x.data(), 20000);
    std::vector<double> u(60000), ref(60000);
    fmm.evaluate(f.data(), u.data());
    double t2 = omp_get_wtime();
    direct_sum<Stokeslet>(x.data(), 20000, f.data(), x.data(), 20000, ref.data());
    double t3 = omp_get_wtime();
    const auto& t = fmm.timings();
    std::printf("p=%d ops %.2fs (cache %d) fmm %.3f direct %.3f err %.3e | tree %.3f p2m %.3f m2m %.3f m2l %.3f x %.3f l2l %.3f p2p %.3f l2p %.3f\n", p, t1-t0, fmm.operators().loaded_from_cache(), t2-t1, t3-t2, rel_l2(u, ref),
      t.tree, t.p2m, t.m2m, t.m2l, t.x_list, t.l2l, t.p2p, t.l2p);
  }
}
