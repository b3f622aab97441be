#pragma once
// capsflow::fmm calibration — tolerance -> order, default leaf size, and the measured crossover
// at which the FMM beats direct summation, one table per kernel (CalibrationOf<Kernel>: the
// Stokeslet's for every kernel without its own). Measured with perf/fmm/fmm_bench on the
// development machine (2 threads, AVX-512; see perf/fmm/RESULTS.md for the commands and raw numbers).
// The functions below take the kernel as a template argument, the Stokeslet by default.
#include <cstddef>

namespace capsflow::fmm {

struct Stokeslet;
struct Stresslet;

struct CalibrationRow {
  double tolerance;        ///< the row applies to requested tolerances >= this value
  int order;               ///< order p whose worst measured rel. L2 error is below `tolerance`
  int leaf_size;           ///< tuned points per leaf for that order
  std::size_t crossover;   ///< N (sources = targets, sphere surface) above which FMM < direct
};

// Ordered from loose to tight. `order` is the lowest p whose WORST relative L2 error over the
// sphere, spheroid (a/b = 1.4), uniform-cube and clustered distributions (N = 1e4, sources =
// targets and 3000 separate targets, 64 points per leaf, all targets checked;
// perf/fmm/order_sweep.sh, results in perf/fmm/results/order_sweep_*.jsonl) was below the
// tolerance (p = 8 only from 2e-6: its worst case outside this matrix, clustered points with
// separate targets and another density, reached 1.08e-6). p <= 7 from the first campaign; p >= 8 re-measured with the factored
// pseudo-inverses (operators.hpp, PinvFactors):
//   p:      4        5        6        7        8        9        10       11       12       13       14
//   worst:  1.14e-3  1.99e-3  4.4e-5   2.3e-6   7.7e-7   5.9e-8   1.1e-8   3.4e-9   7.3e-10  2.8e-10  7.5e-11
// (odd p = 5 is worse than p = 4). Before the factored pseudo-inverses, p >= 10 stalled at
// 1.5e-8–3.7e-8 (perf/fmm/results/order_sweep_before.jsonl).
// leaf_size: measured (perf/fmm/leaf_bie.sh, results/leaf_bie_stokeslet.jsonl,
// quiet machine, 2 threads, medians of 5): random points on the sphere at the boundary integral's
// sizes (3 sources per target: 30 720 × 10 242, 122 880 × 40 962, 491 520 × 163 842) and sources =
// targets at N = 1e5, leaves 200–1 600; the leaf whose worst loss against the best leaf of each case
// is smallest: 400 at p = 4 (1.16), 1 000 at p = 6 (1.08), 1 300 at p = 7–12 (1.04–1.22; p = 11, 13,
// 14 not measured, same). Leaves of 200–600 (right when M2L was slower) cost 1.5–3.3×
// at these sizes: at 600 the trees are one level deeper (e.g. 122 880 × 40 962 at p = 9: 0.37 s
// against 0.20 s). crossover: N at which setup + one evaluation beats direct_sum (sphere,
// sources = targets, 2 threads, quiet machine), measured with these leaves
// (fmm_bench --dist sphere --n N --reps 3, N = 4 000–128 000, log-log between the last two sizes
// where the order changes; perf/fmm/results/crossover-leaf1300/): 6 203 at p = 6, 8 165 at p = 9,
// 12 604 at p = 10, 21 107 at p = 11, 21 304 at p = 12, 26 234 at p = 13, 26 005 at p = 14, rounded
// up (p = 14 takes p = 13's). From p = 11 on a tree level added near N = 16 000 costs more than it
// saves (the FMM is 1.4–2.4× the direct sum there, 1.0–1.1× at 8 000), hence the jump. p = 7, 8 are
// INTERPOLATED geometrically between p = 6 and 9. p = 4 (--tol 2e-3, N = 500–32 000): the FMM is
// 0.6–0.9× the direct sum from N = 1 000 on and equal at 500, where both take under a millisecond
// (the clock's resolution): 1 000. With leaves of 200–600 the crossover was 11 000 at p = 9 and an
// extrapolated 15 000 at p = 11.
// Sources != targets use the geometric mean sqrt(n_src·n_trg).
inline constexpr CalibrationRow kCalibration[] = {
    {2e-3, 4, 400, 1000},
    {1e-4, 6, 1000, 6300},
    {1e-5, 7, 1300, 6800},
    {2e-6, 8, 1300, 7500},  // not 1e-6: a clustered case reached 1.08e-6 at p = 8 (multi-density test)
    {1e-7, 9, 1300, 8200},
    {2e-8, 10, 1300, 12700},
    {4e-9, 11, 1300, 21200},
    {1e-9, 12, 1300, 21400},
    {3e-10, 13, 1300, 26300},
    {0.0, 14, 1300, 26300},
};

// The stresslet (double layer, stresslet.hpp), calibrated the same way over 20 cases: the
// Stokeslet's 8 with 6 random density components per source (perf/fmm/order_sweep.sh BUILD OUT
// "4 ... 14" stresslet, results/order_sweep_stresslet.jsonl); 4 with the boundary integral's
// density, a smooth double layer f = w·u(y), n = normal on the sphere and spheroid, sources =
// targets and 3000 separate targets (SURFACE_ONLY=1 ..., results/order_sweep_stresslet_surface.jsonl);
// and 8 with random f and the outward normals (fmm_bench --density surface-random), on the sphere
// and spheroid, N = 1e4 with 64 points per leaf as above and N = 3000 with 48 (sources = targets,
// and 3000 / 1000 separate targets), seeds 1–3 (results/order_sweep_stresslet_surface_random.jsonl).
// Worst relative L2 error by order:
//   p:          4       5       6       7       8       9       10      11      12      13       14
//   random:     8.1e-4  4.1e-4  3.4e-5  2.7e-6  7.4e-7  9.5e-8  2.2e-8  5.3e-9  1.3e-9  6.1e-10  1.7e-10
//   surface:    2.8e-3  1.1e-3  7.7e-5  5.0e-6  1.6e-6  1.5e-7  2.9e-8  7.4e-9  1.8e-9  8.0e-10  1.9e-10
//   surf.-rand: 1.2e-2  5.6e-3  4.7e-4  4.0e-5  1.1e-5  1.4e-6  3.3e-7  8.1e-8  2.2e-8  1.8e-8   1.7e-8
// A row's tolerance is about twice the worst of the three. Random f with the outward normals is
// the hardest case at every order: on the sphere r·n = −|r|²/2 turns each pair into a 1/|r| term,
// so the sum is far smaller than its terms (a constant f gives f inside, 0 outside). Read off the
// first two cases alone, the table ran a requested 1e-6 at p = 9, which this case misses
// (1.0e-6–1.4e-6; found by tests/python/test_fmm_stresslet.py with 48 points per leaf). One draw
// of the 24 (spheroid, N = 1e4, 3000 separate targets, seed 2) stalls at 1.7e-8–1.8e-8 from p = 13
// on (2.2e-8 at p = 12); the others reach 8.4e-9 at p = 13 and 3.4e-9 at p = 14. So p = 13 buys
// little over p = 12, and the accuracy floor below is twice that draw's.
// leaf_size: measured for the stresslet (perf/fmm/stresslet_bench.sh §4, quiet machine,
// results/stresslet/leaf.jsonl; sphere, leaves 200–800): 800 was fastest at p = 6, 9 and 12 with
// N = 1e5 (by 9 %, 10 % and 32 % over 600), 600 at p = 9 with N = 1e6 (800 4.6 % slower); 800 is
// the leaf whose worst loss is smallest there. From p = 9 on it is 1 300, the Stokeslet's: on the
// double layer's own points (edge midpoints as sources, nodes as targets; icosphere levels 5–7,
// spheroids a/b = 1, 1.4, 2; perf/bie/double_layer_leaf.cpp, results in
// perf/bie/double_layer_leaf.jsonl) 800 adds a tree level where 1 300 does not, and costs up to
// 1.83× at p = 9 (1.62× on the Fig. 4 capsule at 81 920 elements, 1.25× at 327 680) and 1.76× with
// the refresh pass's four densities at p = 10; 1 300 loses at most 1.56× (20 480 elements, where a
// leaf of 2 000 wins and loses 1.2–1.5× at 327 680: no one leaf wins at every size). At p = 6 and
// 7, 800 and 1 300 trade places by shape (worst losses 1.03 / 1.24 and 1.24 / 1.29): 800 stays.
// p = 8 is not measured and keeps 800; p ≥ 11 are not measured and follow p = 9 and 10.
// crossover: measured at p = 6, 9, 12 (§5, results/stresslet/crossover.jsonl; sphere, sources =
// targets, set-up + one evaluation against direct_sum<Stresslet>, log-log between the sizes
// 4000–64000, rounded up): 7 300, 15 000, 40 000 — later than the Stokeslet's of the time (6 000,
// 11 000, 18 000) because the stresslet's direct sum is 1.6x faster per pair (3.9 against 2.4 G pairs/s).
// Measured with the leaves of the time (300 at p = 6, 600 at p = 9 and 12). p = 7, 8, 10, 11 are
// INTERPOLATED geometrically between the measured orders; p = 4, 5 EXTRAPOLATED (the Stokeslet's
// at the same order × 7300/6000), p = 13, 14 EXTRAPOLATED (+20 % per order, the rule the
// Stokeslet's column followed then).
inline constexpr CalibrationRow kStressletCalibration[] = {
    {2.5e-2, 4, 800, 4900},
    {1.2e-2, 5, 800, 6100},
    {1e-3, 6, 800, 7300},
    {8e-5, 7, 800, 9300},
    {2.5e-5, 8, 800, 11800},
    {3e-6, 9, 1300, 15000},
    {7e-7, 10, 1300, 20800},
    {1.7e-7, 11, 1300, 28900},
    {4.5e-8, 12, 1300, 40000},
    {4e-8, 13, 1300, 48000},
    {0.0, 14, 1300, 58000},
};

/// A kernel's table (rows from loose to tight) and the smallest relative L2 error its FMM reaches
/// reliably in double precision (tighter requests get the last row's order and this accuracy).
struct CalibrationTable {
  const CalibrationRow* rows;
  int size;
  double accuracy_floor;
};

template <class Kernel>
struct CalibrationOf {  // the Stokeslet's (measured worst 7.5e-11 at p = 14), for every kernel without its own
  static constexpr CalibrationTable table{kCalibration, sizeof(kCalibration) / sizeof(kCalibration[0]), 1e-10};
};
template <>
struct CalibrationOf<Stresslet> {  // measured worst 1.7e-8 at p = 14 (random f, outward normals; above)
  static constexpr CalibrationTable table{
      kStressletCalibration, sizeof(kStressletCalibration) / sizeof(kStressletCalibration[0]), 4e-8};
};

template <class Kernel = Stokeslet>
constexpr double accuracy_floor() { return CalibrationOf<Kernel>::table.accuracy_floor; }

template <class Kernel = Stokeslet>
const CalibrationRow& calibration_for(double tolerance) {
  constexpr CalibrationTable t = CalibrationOf<Kernel>::table;
  for (int i = 0; i < t.size; ++i)
    if (tolerance >= t.rows[i].tolerance) return t.rows[i];
  return t.rows[t.size - 1];
}

/// Order p to reach a relative L2 error <= tolerance.
template <class Kernel = Stokeslet>
int order_for_tolerance(double tolerance) { return calibration_for<Kernel>(tolerance).order; }

/// The loosest tolerance whose row has order p (calibration_for(it).order == p); −1 if no row has it.
template <class Kernel = Stokeslet>
double tolerance_for_order(int order) {
  constexpr CalibrationTable t = CalibrationOf<Kernel>::table;
  for (int i = 0; i < t.size; ++i)
    if (t.rows[i].order == order) return t.rows[i].tolerance;
  return -1.0;
}

/// Default points per leaf for an order.
template <class Kernel = Stokeslet>
int default_leaf_size(int order) {
  constexpr CalibrationTable t = CalibrationOf<Kernel>::table;
  for (int i = 0; i < t.size; ++i)
    if (t.rows[i].order >= order) return t.rows[i].leaf_size;
  return t.rows[t.size - 1].leaf_size;
}

/// Measured crossover: for n_src·n_trg below crossover², direct_sum is faster than setup +
/// one evaluation of the FMM at this tolerance. Use for backend = "auto".
template <class Kernel = Stokeslet>
std::size_t direct_crossover(double tolerance) { return calibration_for<Kernel>(tolerance).crossover; }

template <class Kernel = Stokeslet>
bool prefer_direct(std::size_t n_src, std::size_t n_trg, double tolerance) {
  const double c = static_cast<double>(direct_crossover<Kernel>(tolerance));
  return static_cast<double>(n_src) * static_cast<double>(n_trg) < c * c;
}

}  // namespace capsflow::fmm
