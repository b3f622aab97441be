#pragma once
// The sizes below which a loop of capsflow::shell runs on one thread: an OpenMP team costs a fork
// and a barrier (with OMP_WAIT_POLICY=passive, a futex wake-up per thread), which a short loop does
// not repay. They never change a result: every parallel loop writes disjoint entries or sums in
// fixed chunks (parallel.hpp), so the output is bit-identical on or off the team.
//
// Measurement: perf/shell/parallel_thresholds (built with -DCAPSFLOW_BENCHMARKS=ON) times what an
// OpenMP team costs and each loop family's serial cost per item, and prints the break-even size
// at which two threads pay off beside each value here; the values and that measurement are in
// docs/shell.md §2.7 (2 threads, quiet machine, 2026-12-01: a team costs about 50 µs here). A
// value within a factor of two of its break-even is kept; three that were 8–25 times below theirs
// were raised to it.
namespace capsflow::shell {

/// Loops over nodes with a few dozen flops per node (packing the element-pass input, the
/// rotation residual, triad rotations, nodal normals, mass-matrix rows).
inline constexpr int kParallelNodes = 4096;
/// Elements of the mass-matrix assembly, one team for the element areas, the nodal rows and the
/// lumped initial guess of the load recovery (which had its own team above 2048 nodes).
inline constexpr int kParallelAreaElements = 4096;
/// Elements of a GSMB element pass, which runs as one team (node-wise prologue, elements, node-wise
/// sums) with one to three TeamBarrier waits: ~450 ns per element against ~50 µs for the team and a
/// barrier assumed at most half of that gives a break-even near 330 elements; this is about twice
/// that. An estimate until re-measured on a quiet machine (docs/shell.md §2.7).
inline constexpr int kParallelGsmbPass = 768;
/// Elements of the membrane-only force pass, one team with one barrier (was a team per colour
/// above 4096 elements per colour): ~18–21 ns per element against a team and a barrier (~50 µs +
/// B) gives a break-even near 6 000 elements; this is about twice that. An estimate until
/// re-measured (docs/shell.md §2.7).
inline constexpr int kParallelMembranePass = 12288;
/// Matrix rows of the stand-alone sparse product (spmv) and block rows of the PCG preconditioner
/// set-up (was 4096; ~3 ns per row, break-even ~35 000 rows).
inline constexpr int kParallelRows = 32768;
/// Entries (rows × right-hand sides) of a PCG solve, which runs as one team per solve with three
/// TeamBarrier waits per iteration. Estimate, to be re-measured (docs/shell.md §2.7): a solve of
/// ~15 iterations at ~10–15 ns per entry and iteration saves half of that on two threads against
/// one team (~50 µs) and 45 spinning barriers (~1 µs each when both threads run): break-even near
/// 1 500 entries; this is 1.4 times that.
inline constexpr long kParallelPcgEntries = 2048;
/// Terms of a deterministic sum (par::det_sum) (was 8192; 0.5 ns per term, break-even ~190 000).
inline constexpr long kParallelSumTerms = 131072;

}  // namespace capsflow::shell
