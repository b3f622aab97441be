// parallel_thresholds: the measurement behind shell/parallel_thresholds.hpp. A loop of n items
// of serial cost c each takes n·c on one thread and about F + n·c/T on T threads, F being what an
// OpenMP team costs (fork, wake-up of the sleeping workers under OMP_WAIT_POLICY=passive, the
// closing barrier). Two threads pay off above the break-even n* = F·T / ((T − 1)·c). This program
// measures F (empty parallel loops, median), B (one par::TeamBarrier wait inside a running team,
// median over 30 waits; beside it OpenMP's own barrier under the same policy, for comparison) and
// c per loop family (the real shell functions on one thread, median time per item), and prints
// n* beside the threshold in use, with the overhead the guarded work pays per pass over its items:
// F + B for an element pass or the mass assembly (one team, one barrier), F + 2·I·B for a PCG solve
// of I iterations (one team per solve, two barriers per iteration; n* is then per iteration).
//
// usage: OMP_WAIT_POLICY=passive OMP_NUM_THREADS=2 parallel_thresholds [level=6] [reps=15]
// (capsflow runs with the passive policy; run on a quiet machine: the numbers are timings).
// The per-item cost of the area family is measured on the function that contains the loop
// (assemble), so it is an upper bound and its n* a lower bound.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "capsflow/shell/director.hpp"
#include "capsflow/shell/gsmb_wall.hpp"
#include "capsflow/shell/load_recovery.hpp"
#include "capsflow/shell/parallel.hpp"
#include "capsflow/shell/parallel_thresholds.hpp"
#include "capsflow/shell/pcg.hpp"
#include "capsflow/shell/wall.hpp"
#include "test_meshes.hpp"

using namespace capsflow::shell;
using clk = std::chrono::steady_clock;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Median seconds of `reps` calls of f on one thread.
double serial_seconds(int reps, const std::function<void()>& f) {
  omp_set_num_threads(1);
  f();  // warm-up: allocations, caches
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) {
    const auto a = clk::now();
    f();
    t.push_back(std::chrono::duration<double>(clk::now() - a).count());
  }
  return median(t);
}

// Median seconds of an OpenMP team on `threads` threads around a loop of `threads` trivial items,
// with serial work in between (as between capsflow's loops) so that passive workers fall asleep.
double team_seconds(int threads) {
  omp_set_num_threads(threads);
  std::vector<double> sink(64, 0.0), t;
  volatile double gap = 0;
  for (int r = 0; r < 3000; ++r) {
    for (int k = 0; k < 2000; ++k) gap = gap + 1e-9 * k;  // ~ microseconds of serial work
    const auto a = clk::now();
#pragma omp parallel for schedule(static)
    for (int i = 0; i < threads; ++i) sink[8 * i] += 1.0;
    t.push_back(std::chrono::duration<double>(clk::now() - a).count());
  }
  return median(t);
}

// Median seconds of one barrier wait inside a running team of `threads` (30 waits per team, the
// team's own cost removed): TeamBarrier when `team_barrier`, else OpenMP's barrier.
double barrier_seconds(int threads, double team, bool team_barrier) {
  omp_set_num_threads(threads);
  std::vector<double> t;
  volatile double gap = 0;
  constexpr int kWaits = 30;
  for (int r = 0; r < 1000; ++r) {
    for (int k = 0; k < 2000; ++k) gap = gap + 1e-9 * k;
    par::TeamBarrier barrier;
    const auto a = clk::now();
#pragma omp parallel
    {
      for (int k = 0; k < kWaits; ++k) {
        if (team_barrier) {
          barrier.wait(omp_get_num_threads());
        } else {
#pragma omp barrier
        }
      }
    }
    t.push_back(std::chrono::duration<double>(clk::now() - a).count());
  }
  return std::max(0.0, (median(t) - team) / kWaits);
}

// `overhead`: seconds the guarded work pays per pass over its items on a team (see the header).
void report(const char* family, long threshold, double per_item, double overhead, double team, double barrier, int threads,
            long items) {
  const double n_star = overhead * threads / ((threads - 1) * per_item);
  std::printf("{\"family\": \"%s\", \"threshold\": %ld, \"items_timed\": %ld, \"per_item_ns\": %.3f, \"team_us\": %.2f, "
              "\"barrier_us\": %.2f, \"overhead_us\": %.2f, \"threads\": %d, \"break_even_n\": %.0f, "
              "\"ratio_threshold_to_break_even\": %.2f}\n",
              family, threshold, items, 1e9 * per_item, 1e6 * team, 1e6 * barrier, 1e6 * overhead, threads, n_star,
              threshold / n_star);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const int level = argc > 1 ? std::atoi(argv[1]) : 6;
  const int reps = argc > 2 ? std::atoi(argv[2]) : 15;
  const char* policy = std::getenv("OMP_WAIT_POLICY");
  const int threads = std::max(2, omp_get_max_threads());
  std::printf("{\"level\": %d, \"reps\": %d, \"omp_wait_policy\": \"%s\", \"threads\": %d}\n", level, reps,
              policy ? policy : "(unset: libgomp's default spins first; capsflow uses passive)", threads);

  const testing::Mesh m = testing::icosphere(level);
  const Eigen::Index n = m.X.rows(), ne = m.T.rows();
  Points x = m.X;
  for (Eigen::Index i = 0; i < n; ++i) x(i, 0) += 0.3 * m.X(i, 1);  // a sheared sphere
  const double team = team_seconds(threads);
  const double barrier = barrier_seconds(threads, team, true);
  std::printf("{\"team_us\": %.2f, \"team_barrier_us\": %.2f, \"openmp_barrier_us\": %.2f}\n", 1e6 * team,
              1e6 * barrier, 1e6 * barrier_seconds(threads, team, false));
  const double one_barrier = team + barrier;  // an element pass or the assembly: a team and a barrier

  const Topology topo(m.T, n);
  Points normals;
  report("nodes (nodal normals)", kParallelNodes, serial_seconds(reps, [&] { area_weighted_normals(x, topo, normals); }) / n,
         team, team, barrier, threads, n);

  LoadRecovery load(m.T, n);
  Points R = x, q;
  report("area_elements (mass assembly: upper bound)", kParallelAreaElements,
         serial_seconds(reps, [&] { load.assemble(x); }) / ne, one_barrier, team, barrier, threads, ne);

  const SpMatR& M = load.assemble(x);
  std::vector<double> in(M.cols(), 1.0), out(M.rows());
  report("rows (spmv of the mass matrix)", kParallelRows, serial_seconds(reps, [&] { spmv(M, in.data(), out.data()); }) / M.rows(),
         team, team, barrier, threads, M.rows());

  // Three right-hand sides, a fixed number of iterations: the cost per entry and iteration.
  const int iters = 20;
  BlockPcg pcg(1, 3);
  std::vector<double> b(3 * n, 1.0), sol(3 * n);
  report("pcg_entries (BlockPcg, 3 columns, per iteration of a 20-iteration solve)", kParallelPcgEntries,
         serial_seconds(reps, [&] { pcg.solve(M, b.data(), sol.data(), 0.0, iters); }) / (3.0 * n * iters),
         (team + 2 * iters * barrier) / iters, team, barrier, threads, 3 * n);

  std::vector<double> a(8 * n, 0.5), partial;
  report("sum_terms (det_sum)", kParallelSumTerms,
         serial_seconds(reps, [&] { volatile double s = par::det_sum(8 * n, partial, [&](long i) { return a[i] * a[i]; }); (void)s; }) /
             (8.0 * n),
         team, team, barrier, threads, 8 * n);

  const MembraneLaw law = make_law(LawKind::NeoHookean, 1.0);
  MembraneWall membrane(m.X, m.T, law);
  Points Rs;
  report("membrane_pass (membrane forces, per element)", kParallelMembranePass,
         serial_seconds(reps, [&] { membrane.forces(x, Rs); }) / ne, one_barrier, team, barrier, threads, ne);

  // GSMB: converge the rotations at x first; a repeated call then starts converged (no Newton
  // step), so its time is the element passes and the nodal loops around them.
  GsmbOptions opt;
  GsmbWall gsmb(m.X, m.T, law, opt);
  gsmb.forces(x, Rs);
  WallStats stats;
  const double g = serial_seconds(reps, [&] { gsmb.forces(x, Rs, &stats); });
  report("gsmb_pass (GSMB forces from converged rotations, per element)", kParallelGsmbPass, g / ne, one_barrier, team,
         barrier, threads, ne);
  std::printf("{\"gsmb_newton_iterations_per_call\": %d}\n", stats.newton_iterations);
  return 0;
}
