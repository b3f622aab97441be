// pvfmm_stokes_bench — time and accuracy of PVFMM's Stokes velocity FMM (benchmark only; capsflow
// never links PVFMM). Built by perf/peers/build_pvfmm.sh against a PVFMM snapshot.
//
//   pvfmm_stokes_bench POINTS m [--leaf 600] [--reps 3] [--sample 1000] [--seed 1]
//
// POINTS: the text format of fmm_bench --input (perf/fmm/fmm_bench.cpp): first line "n_src n_trg";
// then n_src lines "x y z f1 f2 f3"; then n_trg lines "x y z"; n_trg = 0 means targets = sources.
// m: PVFMM's multipole order (even, 2..16 or so). --leaf: PVFMM's max_pts per leaf.
//
// PVFMM wants coordinates in [0,1)^3: the points are mapped by x' = 0.5 + s (x - c) (c the centre
// of the bounding box of sources and targets, s = 0.9 / its largest side) and the result scaled
// back by s: the Stokeslet is homogeneous of degree -1, G(s r) = G(r) / s.
// PVFMM's stokes_vel kernel (include/kernel.txx) is u = 1/(8 pi) sum (I/r + r r^T / r^3) f with
// r = 0 pairs skipped, the same convention as capsflow's stokeslet, so no other factor is applied;
// "scale_fit" (the least-squares factor a minimising |a u_fmm - u_direct| on the sample) checks
// it: 1 up to the error.
//
// Prints one JSON line: n, ntrg, m, leaf, threads, init_s (PVFMM's operator precomputation or its
// load from $PVFMM_DIR/Precomp_stokes_vel_m<m>.data), setup_s (tree construction + SetupFMM,
// median of reps), eval_s (PtFMM_Evaluate, median of reps), rel_l2_error and max_rel_error against
// a double-precision direct sum on `sample` random targets (same definitions as fmm_bench:
// max_rel_error = largest pointwise error / largest reference magnitude), scale_fit.
#include <mpi.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <pvfmm.hpp>

namespace {
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}
}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s POINTS m [--leaf 600] [--reps 3] [--sample 1000] [--seed 1]\n", argv[0]);
    MPI_Finalize();
    return 2;
  }
  const std::string file = argv[1];
  const int m = std::atoi(argv[2]);
  int leaf = 600, reps = 3, sample = 1000;
  unsigned seed = 1;
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--leaf") leaf = std::atoi(argv[i + 1]);
    else if (k == "--reps") reps = std::atoi(argv[i + 1]);
    else if (k == "--sample") sample = std::atoi(argv[i + 1]);
    else if (k == "--seed") seed = static_cast<unsigned>(std::atoi(argv[i + 1]));
    else { std::fprintf(stderr, "unknown option %s\n", k.c_str()); MPI_Finalize(); return 2; }
  }

  // Read the points (fmm_bench --input format).
  std::ifstream in(file);
  std::size_t ns = 0, nt = 0;
  if (!(in >> ns >> nt)) { std::fprintf(stderr, "cannot read %s\n", file.c_str()); MPI_Finalize(); return 2; }
  std::vector<double> src(3 * ns), f(3 * ns), trg(3 * nt);
  for (std::size_t i = 0; i < ns; ++i) {
    for (int d = 0; d < 3; ++d) in >> src[3 * i + d];
    for (int d = 0; d < 3; ++d) in >> f[3 * i + d];
  }
  for (auto& v : trg) in >> v;
  if (!in) { std::fprintf(stderr, "truncated input %s\n", file.c_str()); MPI_Finalize(); return 2; }
  const bool same = nt == 0;
  if (same) { trg = src; nt = ns; }

  // Map into [0,1)^3.
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (const auto* p : {&src, &trg})
    for (std::size_t i = 0; i < p->size(); ++i) {
      lo[i % 3] = std::min(lo[i % 3], (*p)[i]);
      hi[i % 3] = std::max(hi[i % 3], (*p)[i]);
    }
  double side = 0, c[3];
  for (int d = 0; d < 3; ++d) { side = std::max(side, hi[d] - lo[d]); c[d] = 0.5 * (lo[d] + hi[d]); }
  const double s = 0.9 / (side > 0 ? side : 1.0);
  std::vector<double> src_u(src.size()), trg_u(trg.size());
  for (std::size_t i = 0; i < src.size(); ++i) src_u[i] = 0.5 + s * (src[i] - c[i % 3]);
  for (std::size_t i = 0; i < trg.size(); ++i) trg_u[i] = 0.5 + s * (trg[i] - c[i % 3]);

  MPI_Comm comm = MPI_COMM_WORLD;
  const bool profile = std::getenv("PVFMM_PROFILE") != nullptr;  // PVFMM's own phase profile, on stderr
  if (profile) pvfmm::Profile::Enable(true);
  const pvfmm::Kernel<double>& kernel = pvfmm::StokesKernel<double>::velocity();
  std::vector<double> dl_coord, dl_den;  // no double layer
  pvfmm::mem::MemoryManager mem_mgr(10000000);

  double t = MPI_Wtime();
  pvfmm::PtFMM<double> matrices(&mem_mgr);
  matrices.Initialize(m, comm, &kernel);
  const double init_s = MPI_Wtime() - t;

  std::vector<double> setup_t, eval_t, u;
  for (int r = 0; r < std::max(1, reps); ++r) {
    t = MPI_Wtime();
    auto* tree = pvfmm::PtFMM_CreateTree(src_u, f, dl_coord, dl_den, trg_u, comm, leaf, pvfmm::FreeSpace);
    tree->SetupFMM(&matrices);
    setup_t.push_back(MPI_Wtime() - t);
    t = MPI_Wtime();
    pvfmm::PtFMM_Evaluate(tree, u, nt);
    eval_t.push_back(MPI_Wtime() - t);
    delete tree;
  }
  for (auto& v : u) v *= s;  // back to the original coordinates

  // Direct sum (double precision, original coordinates) on a random sample of targets.
  std::mt19937_64 g(seed);
  std::vector<std::size_t> idx(nt);
  for (std::size_t i = 0; i < nt; ++i) idx[i] = i;
  const std::size_t ks = std::min<std::size_t>(static_cast<std::size_t>(std::max(1, sample)), nt);
  for (std::size_t i = 0; i < ks; ++i) std::swap(idx[i], idx[i + std::uniform_int_distribution<std::size_t>(0, nt - 1 - i)(g)]);
  std::vector<double> ref(3 * ks, 0.0);
  const double c8pi = 1.0 / (8.0 * 3.14159265358979323846);
#pragma omp parallel for schedule(dynamic, 8)
  for (std::size_t k = 0; k < ks; ++k) {
    const double* x = &trg[3 * idx[k]];
    double a0 = 0, a1 = 0, a2 = 0;
    for (std::size_t j = 0; j < ns; ++j) {
      const double r0 = x[0] - src[3 * j], r1 = x[1] - src[3 * j + 1], r2 = x[2] - src[3 * j + 2];
      const double rr = r0 * r0 + r1 * r1 + r2 * r2;
      if (rr == 0) continue;
      const double ri = 1.0 / std::sqrt(rr);
      const double* fj = &f[3 * j];
      const double ip = (r0 * fj[0] + r1 * fj[1] + r2 * fj[2]) * ri * ri;
      a0 += ri * (fj[0] + r0 * ip);
      a1 += ri * (fj[1] + r1 * ip);
      a2 += ri * (fj[2] + r2 * ip);
    }
    ref[3 * k] = c8pi * a0; ref[3 * k + 1] = c8pi * a1; ref[3 * k + 2] = c8pi * a2;
  }
  double e2 = 0, r2 = 0, emax = 0, rmax = 0, uu = 0, ur = 0;
  for (std::size_t k = 0; k < ks; ++k) {
    double ek = 0, rk = 0;
    for (int d = 0; d < 3; ++d) {
      const double a = u[3 * idx[k] + d], b = ref[3 * k + d];
      ek += (a - b) * (a - b); rk += b * b; uu += a * a; ur += a * b;
    }
    e2 += ek; r2 += rk;
    emax = std::max(emax, std::sqrt(ek)); rmax = std::max(rmax, std::sqrt(rk));
  }
  std::printf("{\"code\": \"pvfmm\", \"input\": \"%s\", \"n\": %zu, \"ntrg\": %zu, \"m\": %d, \"leaf\": %d, "
              "\"threads\": %d, \"reps\": %d, \"init_s\": %.4f, \"setup_s\": %.4f, \"eval_s\": %.4f, "
              "\"total_s\": %.4f, \"rel_l2_error\": %.3e, \"max_rel_error\": %.3e, \"scale_fit\": %.12f, "
              "\"sample\": %zu}\n",
              file.c_str(), ns, same ? std::size_t(0) : nt, m, leaf, omp_get_max_threads(), std::max(1, reps), init_s,
              median(setup_t), median(eval_t), median(setup_t) + median(eval_t), std::sqrt(e2 / r2), emax / rmax,
              uu > 0 ? ur / uu : 0.0, ks);
  if (profile) { std::fflush(stdout); pvfmm::Profile::print(&comm); }
  MPI_Finalize();
  return 0;
}
