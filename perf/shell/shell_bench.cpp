// shell_bench: time of one RK stage of the wall (rotation solve + R_s, then load recovery
// M(x) q = R_s) from a warm start, and of the membrane-only load, on icosphere-based spheroid
// meshes of 1280 ... 81920 elements. Prints one JSON line per (mesh, model).
//
// Scenario (the paper's case, §4.1): prolate spheroid a/b = 1.4 (a b^2 = 1), GSMB wall with
// alpha = h = 0.03, nu = 0.5, neo-Hookean membrane, G_s = 1/Ca_s with Ca_v = 0.003 (G_s = 1/(Ca_v/alpha)
// ... any value: times do not depend on it). The wall is first deformed by a finite simple shear
// (x = F X, F = I + 0.3 e1 e2^T) and its rotations converged (not timed); then each timed stage
// moves the nodes by dt * L x (simple shear L = e1 e2^T, gamma_dot dt = 1e-4, as the paper's step)
// and calls forces() + LoadRecovery::solve(): the warm start is the previous stage's solution.
//
// usage: shell_bench [max_level=6] [reps=20]      (OMP_NUM_THREADS sets the threads)
// median_cpu_ms_total is the process CPU time per stage (all threads): with 1 thread it is what
// the wall time would be on an idle machine, a useful figure when the machine is shared.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "capsflow/shell/gsmb_wall.hpp"
#include "capsflow/shell/load_recovery.hpp"
#include "test_meshes.hpp"

using namespace capsflow::shell;
using clk = std::chrono::steady_clock;

static double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
static double loadavg() {  // 1-minute load average of the machine (context for the timings)
  double l = -1;
  if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf", &l) != 1) l = -1;
    std::fclose(f);
  }
  return l;
}
static double ms(clk::time_point a, clk::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

int main(int argc, char** argv) {
  const int max_level = argc > 1 ? std::atoi(argv[1]) : 6;
  const int reps = argc > 2 ? std::atoi(argv[2]) : 20;
  const double alpha = 0.03, Ca_v = 0.003, Gs = alpha / Ca_v, dt = 1e-4;
  for (int level = 3; level <= max_level; ++level) {
    testing::Mesh m = testing::icosphere(level);
    const double b = std::pow(1.4, -1.0 / 3.0), a = 1.4 * b;
    Points X = m.X;
    X.col(0) *= b;
    X.col(1) *= b;
    X.col(2) *= a;
    const Eigen::Index n = X.rows();
    Points x = X;
    for (Eigen::Index i = 0; i < n; ++i) x(i, 0) += 0.3 * X(i, 1);
    const MembraneLaw law = make_law("nh", Gs);
    GsmbOptions opt;
    opt.thickness = alpha;
    opt.poisson = 0.5;
    GsmbWall wall(X, m.T, law, opt);
    LoadRecovery lr(m.T, n);
    lr.set_warm_start(true);  // previous stage's q as the initial guess
    Points R, q;
    WallStats st;
    const auto c0 = clk::now();
    wall.forces(x, R, &st);  // cold solve from the reference directors
    const double cold_ms = ms(c0, clk::now());
    const int cold_newton = st.newton_iterations, cold_cg = st.cg_iterations;
    lr.solve(x, R, q);
    std::vector<double> tf, tl, tt, tcpu;
    int newton = 0, cg = 0, lcg = 0, newton_max = 0;
    double res_max = 0;
    for (int r = 0; r < reps; ++r) {
      for (Eigen::Index i = 0; i < n; ++i) x(i, 0) += dt * x(i, 1);
      const std::clock_t c0s = std::clock();
      const auto t0 = clk::now();
      wall.forces(x, R, &st);
      const auto t1 = clk::now();
      const int it = lr.solve(x, R, q);
      const auto t2 = clk::now();
      tcpu.push_back(1000.0 * double(std::clock() - c0s) / CLOCKS_PER_SEC);
      tf.push_back(ms(t0, t1));
      tl.push_back(ms(t1, t2));
      tt.push_back(ms(t0, t2));
      newton += st.newton_iterations;
      newton_max = std::max(newton_max, st.newton_iterations);
      cg += st.cg_iterations;
      lcg += it;
      res_max = std::max(res_max, st.residual);
    }
    std::printf(
        "{\"bench\":\"shell_stage\",\"model\":\"gsmb\",\"law\":\"nh\",\"elements\":%ld,\"nodes\":%ld,"
        "\"threads\":%d,\"reps\":%d,\"median_ms_total\":%.3f,\"median_ms_rotation_solve\":%.3f,"
        "\"median_ms_load_recovery\":%.3f,\"min_ms_total\":%.3f,\"newton_per_stage\":%.2f,"
        "\"newton_max\":%d,\"cg_per_stage\":%.1f,\"load_cg_per_stage\":%.1f,\"max_residual\":%.2e,"
        "\"cold_ms\":%.1f,\"cold_newton\":%d,\"cold_cg\":%d,\"median_cpu_ms_total\":%.3f,\"load\":%.2f}\n",
        static_cast<long>(m.T.rows()), static_cast<long>(n), omp_get_max_threads(), reps, median(tt),
        median(tf), median(tl), *std::min_element(tt.begin(), tt.end()), double(newton) / reps,
        newton_max, double(cg) / reps, double(lcg) / reps, res_max, cold_ms, cold_newton, cold_cg,
        median(tcpu), loadavg());
    std::fflush(stdout);
    // membrane-only wall: explicit load
    MembraneWall mw(X, m.T, law);
    std::vector<double> tm, tml;
    for (int r = 0; r < reps; ++r) {
      const auto t0 = clk::now();
      mw.forces(x, R);
      const auto t1 = clk::now();
      lr.solve(x, R, q);
      const auto t2 = clk::now();
      tm.push_back(ms(t0, t1));
      tml.push_back(ms(t0, t2));
    }
    std::printf(
        "{\"bench\":\"shell_stage\",\"model\":\"membrane\",\"law\":\"nh\",\"elements\":%ld,\"nodes\":%ld,"
        "\"threads\":%d,\"reps\":%d,\"median_ms_forces\":%.3f,\"median_ms_forces_plus_load_recovery\":%.3f}\n",
        static_cast<long>(m.T.rows()), static_cast<long>(n), omp_get_max_threads(), reps, median(tm),
        median(tml));
    std::fflush(stdout);
  }
  return 0;
}
