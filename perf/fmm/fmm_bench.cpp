// fmm_bench — time and accuracy of capsflow's KIFMM against its own direct summation.
//
//   fmm_bench --dist sphere|spheroid|cube|clustered --n 100000 [--ntrg M] [--tol 1e-6 | --order p]
//             [--leaf L] [--threads T] [--reps 3] [--sample 1000]
//             [--kernel stokeslet|stresslet|laplace[,...]] [--cache-dir DIR] [--seed S] [--densities K]
//             [--density random|surface|surface-random] [--single-pairs]
//   fmm_bench --input points.txt [--output velocities.txt] [--tol ..] ...
//
// Prints one JSON line per run with: dist, n (sources), ntrg, tol, order, leaf, threads,
// setup_s (tree + lists, median), eval_s (median of reps), rel_l2_error and max_rel_error
// (against direct summation on `sample` random targets; max_rel_error is the largest pointwise
// error divided by the largest reference magnitude), direct_s (direct sum of all targets,
// extrapolated from the sample), ops_s (operator build or cache load), phase breakdown.
// --ntrg M (M > 0) uses M separate targets from the same distribution (sources != targets);
// default: targets = sources.
// --densities K (K > 1): K random density vectors evaluated by ONE evaluate(f, u, K) call; eval_s
// is the median time of that call, eval_seq_s the median time of K separate single-density
// calls, multi_speedup = eval_seq_s / eval_s, multi_vs_single = relative L2 difference between
// the two results (all densities); errors are those of density 0.
//
// --kernel a,b,...: the kernels one after the other in one process on the same points (one JSON
// line each), for ratios measured side by side (perf/fmm/stresslet_bench.sh). The stresslet's
// density is 6 random components per source (f then n, stresslet.hpp); --density surface (the
// stresslet on --dist sphere|spheroid) gives it a smooth double layer instead, n the outward
// normal and f = w·u(y) (tests/fmm/points.hpp, surface_double_layer), as the boundary integral uses it;
// --single-pairs: the near field's pairs in single precision (FmmOptions::single_precision_pairs).
// --density surface-random keeps the outward normals with random f (random_surface_double_layer).
//
// File format of --input (text): first line "n_src n_trg"; then n_src lines "x y z f1 f2 f3"
// (one density value per component of the kernel: 6 for the stresslet); then n_trg lines "x y z".
// n_trg = 0 means targets = sources. --output writes n_trg lines "u1 u2 u3" (%.17g), in input order.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/fmm.hpp"
#include "capsflow/fmm/laplace.hpp"
#include "capsflow/fmm/stokeslet.hpp"
#include "capsflow/fmm/stresslet.hpp"
#include "points.hpp"

using namespace capsflow::fmm;

namespace {
double now() { return omp_get_wtime(); }
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}
struct Args {
  std::string dist = "sphere", kernel = "stokeslet", input, output, cache_dir, density = "random";
  std::size_t n = 10000, ntrg = 0;
  double tol = 1e-6;
  int order = 0, leaf = 0, threads = 0, reps = 3, sample = 1000, densities = 1;
  bool single_pairs = false;
  unsigned seed = 1;
};

template <class Kernel>
int run(const Args& a) {
  constexpr int SD = Kernel::src_dim, TD = Kernel::trg_dim;
  std::vector<double> src, f, trg;
  bool same = true;
  if (!a.input.empty()) {
    std::ifstream in(a.input);
    std::size_t ns = 0, nt = 0;
    if (!(in >> ns >> nt)) { std::fprintf(stderr, "fmm_bench: cannot read %s\n", a.input.c_str()); return 2; }
    src.resize(3 * ns); f.resize(SD * ns); trg.resize(3 * nt);
    for (std::size_t i = 0; i < ns; ++i) {
      for (int d = 0; d < 3; ++d) in >> src[3 * i + d];
      for (int k = 0; k < SD; ++k) in >> f[SD * i + k];
    }
    for (std::size_t i = 0; i < 3 * nt; ++i) in >> trg[i];
    if (!in) { std::fprintf(stderr, "fmm_bench: truncated input %s\n", a.input.c_str()); return 2; }
    same = nt == 0;
  } else {
    src = capsflow::fmm::testing::make_points(a.dist, a.n, a.seed);
    f = capsflow::fmm::testing::random_density(SD * a.n * std::max(1, a.densities), a.seed + 1);
    if (a.density == "surface" || a.density == "surface-random") {
      if (SD != 6 || (a.dist != "sphere" && a.dist != "spheroid") || a.densities > 1) {
        std::fprintf(stderr, "fmm_bench: --density %s needs the stresslet, one density, --dist sphere|spheroid\n",
                     a.density.c_str());
        return 2;
      }
      f = a.density == "surface" ? capsflow::fmm::testing::surface_double_layer(a.dist, src)
                                 : capsflow::fmm::testing::random_surface_double_layer(a.dist, src, a.seed + 1);
    } else if (a.density != "random") {
      std::fprintf(stderr, "fmm_bench: unknown --density %s\n", a.density.c_str());
      return 2;
    }
    if (a.ntrg > 0) { trg = capsflow::fmm::testing::make_points(a.dist, a.ntrg, a.seed + 2); same = false; }
  }
  if (same) trg = src;
  const std::size_t ns = src.size() / 3, nt = trg.size() / 3;
  FmmOptions o;
  o.tolerance = a.tol; o.order = a.order; o.leaf_size = a.leaf; o.threads = a.threads; o.cache_dir = a.cache_dir;
  o.single_precision_pairs = a.single_pairs;
  double t = now();
  Fmm<Kernel> fmm(o);
  const double ops_s = now() - t;
  const int K = a.input.empty() ? std::max(1, a.densities) : 1;
  std::vector<double> setup_t, eval_t, seq_t, u(TD * nt * K), useq;
  FmmTimings tm;
  for (int r = 0; r < std::max(1, a.reps); ++r) {
    t = now();
    fmm.setup(src.data(), ns, trg.data(), nt);
    setup_t.push_back(now() - t);
    t = now();
    fmm.evaluate(f.data(), u.data(), K);
    eval_t.push_back(now() - t);
    if (eval_t.back() <= median(eval_t)) tm = fmm.timings();
    if (K > 1) {
      useq.assign(u.size(), 0.0);
      t = now();
      for (int d = 0; d < K; ++d) fmm.evaluate(f.data() + SD * ns * d, useq.data() + TD * nt * d);
      seq_t.push_back(now() - t);
    }
  }
  double mv_num = 0, mv_den = 0;
  for (std::size_t i = 0; i < useq.size(); ++i) {
    mv_num += (u[i] - useq[i]) * (u[i] - useq[i]);
    mv_den += useq[i] * useq[i];
  }
  if (!a.output.empty()) {
    std::FILE* fo = std::fopen(a.output.c_str(), "w");
    if (!fo) { std::fprintf(stderr, "fmm_bench: cannot write %s\n", a.output.c_str()); return 2; }
    for (std::size_t i = 0; i < nt; ++i) {
      for (int k = 0; k < TD; ++k) std::fprintf(fo, k ? " %.17g" : "%.17g", u[TD * i + k]);
      std::fprintf(fo, "\n");
    }
    std::fclose(fo);
  }
  // accuracy on sampled targets
  const std::size_t m = std::min<std::size_t>(nt, static_cast<std::size_t>(a.sample));
  std::vector<std::size_t> idx(nt);
  for (std::size_t i = 0; i < nt; ++i) idx[i] = i;
  std::mt19937_64 g(a.seed + 7);
  std::shuffle(idx.begin(), idx.end(), g);
  idx.resize(m);
  std::vector<double> st(3 * m), ref(TD * m), got(TD * m);
  for (std::size_t i = 0; i < m; ++i) {
    for (int d = 0; d < 3; ++d) st[3 * i + d] = trg[3 * idx[i] + d];
    for (int k = 0; k < TD; ++k) got[TD * i + k] = u[TD * idx[i] + k];
  }
  t = now();
  direct_sum<Kernel>(src.data(), ns, f.data(), st.data(), m, ref.data(), a.threads);
  const double direct_sample = now() - t;
  double num = 0, den = 0, maxerr = 0, maxref = 0;
  for (std::size_t i = 0; i < TD * m; ++i) {
    num += (got[i] - ref[i]) * (got[i] - ref[i]);
    den += ref[i] * ref[i];
    maxerr = std::max(maxerr, std::abs(got[i] - ref[i]));
    maxref = std::max(maxref, std::abs(ref[i]));
  }
  const double direct_s = m ? direct_sample * static_cast<double>(nt) / static_cast<double>(m) : 0;
  std::printf("{\"what\":\"fmm\",\"kernel\":\"%s\",\"density\":\"%s\",\"dist\":\"%s\",\"n\":%zu,\"ntrg\":%zu,\"same\":%s,"
              "\"tol\":%g,\"order\":%d,\"leaf\":%d,\"threads\":%d,\"setup_s\":%.4f,\"eval_s\":%.4f,"
              "\"rel_l2_error\":%.3e,\"max_rel_error\":%.3e,\"direct_s\":%.4f,\"direct_pairs_per_s\":%.3e,"
              "\"ops_s\":%.3f,\"ops_cached\":%s,\"levels\":%d,\"nv\":%zu,\"nodes\":%zu,\"leaves\":%zu,"
              "\"phases\":{\"p2p\":%.4f,\"m2l\":%.4f,\"p2m\":%.4f,\"m2m\":%.4f,\"l2l\":%.4f,\"l2p\":%.4f,\"x\":%.4f,\"other\":%.4f,\"m2l_fft\":%.4f,\"m2l_hadamard\":%.4f},"
              "\"densities\":%d,\"eval_seq_s\":%.4f,\"multi_speedup\":%.3f,\"multi_vs_single\":%.2e,"
              "\"single_pairs\":%s,\"isa\":\"%s\"}\n",
              Kernel::name, a.input.empty() ? a.density.c_str() : "file", a.input.empty() ? a.dist.c_str() : "file", ns, nt, same ? "true" : "false",
              a.tol, fmm.order(), fmm.leaf_size(), fmm.threads(), median(setup_t), median(eval_t),
              den > 0 ? std::sqrt(num / den) : 0.0, maxref > 0 ? maxerr / maxref : 0.0, direct_s,
              direct_sample > 0 ? static_cast<double>(ns) * m / direct_sample : 0.0, ops_s,
              fmm.operators().loaded_from_cache() ? "true" : "false", fmm.tree().levels(), fmm.tree().V.item.size(),
              fmm.tree().nodes.size(), fmm.tree().leaves.size(), tm.p2p, tm.m2l, tm.p2m, tm.m2m,
              tm.l2l, tm.l2p, tm.x_list, tm.other, tm.m2l_fft, tm.m2l_hadamard, K, median(seq_t),
              K > 1 && median(eval_t) > 0 ? median(seq_t) / median(eval_t) : 1.0,
              mv_den > 0 ? std::sqrt(mv_num / mv_den) : 0.0, a.single_pairs ? "true" : "false", simd::isa_name());
  std::fflush(stdout);
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto val = [&]() -> std::string {
      if (i + 1 >= argc) { std::fprintf(stderr, "fmm_bench: %s needs a value\n", k.c_str()); std::exit(2); }
      return argv[++i];
    };
    if (k == "--dist") a.dist = val();
    else if (k == "--kernel") a.kernel = val();
    else if (k == "--n") a.n = static_cast<std::size_t>(std::stod(val()));
    else if (k == "--ntrg") a.ntrg = static_cast<std::size_t>(std::stod(val()));
    else if (k == "--tol") a.tol = std::stod(val());
    else if (k == "--order") a.order = std::stoi(val());
    else if (k == "--leaf") a.leaf = std::stoi(val());
    else if (k == "--threads") a.threads = std::stoi(val());
    else if (k == "--reps") a.reps = std::stoi(val());
    else if (k == "--sample") a.sample = std::stoi(val());
    else if (k == "--seed") a.seed = static_cast<unsigned>(std::stoul(val()));
    else if (k == "--input") a.input = val();
    else if (k == "--output") a.output = val();
    else if (k == "--cache-dir") a.cache_dir = val();
    else if (k == "--densities") a.densities = std::stoi(val());
    else if (k == "--density") a.density = val();
    else if (k == "--single-pairs") a.single_pairs = true;
    else if (k == "-h" || k == "--help") {
      std::printf("see the header of perf/fmm/fmm_bench.cpp\n");
      return 0;
    } else { std::fprintf(stderr, "fmm_bench: unknown option %s\n", k.c_str()); return 2; }
  }
  std::size_t at = 0;
  for (;;) {
    const std::size_t comma = a.kernel.find(',', at);
    const std::string k = a.kernel.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    int rc = 2;
    if (k == "laplace") rc = run<Laplace>(a);
    else if (k == "stokeslet") rc = run<Stokeslet>(a);
    else if (k == "stresslet") rc = run<Stresslet>(a);
    else std::fprintf(stderr, "fmm_bench: unknown kernel %s\n", k.c_str());
    if (rc != 0) return rc;
    if (comma == std::string::npos) return 0;
    at = comma + 1;
  }
}
