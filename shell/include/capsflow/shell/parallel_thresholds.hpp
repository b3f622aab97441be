#pragma once
// The sizes below which a loop of capsflow::shell runs on one thread: an OpenMP team costs a fork
// and a barrier (with OMP_WAIT_POLICY=passive, a futex wake-up per thread), which a short loop does
// not repay. They never change a result: every parallel loop writes disjoint entries or sums in
// fixed chunks (parallel.hpp), so the output is bit-identical on or off the team.
//
// Measurement: perf/shell/parallel_thresholds (built with -DCAPSFLOW_BENCHMARKS=ON) times what an
// OpenMP team costs and each loop family's serial cost per item, and prints the break-even size
// at which two threads pay off beside each value here; the values and that measurement are in
// docs/shell.md §2.7. A value within a factor of a few of its break-even is kept: below it the
// loop costs microseconds either way.
namespace capsflow::shell {

/// Loops over nodes with a few dozen flops per node (packing the element-pass input, the
/// rotation residual, triad rotations, nodal normals, mass-matrix rows).
inline constexpr int kParallelNodes = 4096;
/// The lumped initial guess of the load recovery (three divisions per node).
inline constexpr int kParallelLumpedNodes = 2048;
/// Element areas of the mass matrix (one cross product per element).
inline constexpr int kParallelAreaElements = 4096;
/// Elements of one colour in the GSMB element pass (bending + shear kernel, optional membrane).
inline constexpr int kParallelGsmbColour = 256;
/// Elements of one colour in the membrane-only force pass.
inline constexpr int kParallelMembraneColour = 512;
/// Matrix rows of the stand-alone sparse product (spmv) and block rows of the PCG preconditioner
/// set-up.
inline constexpr int kParallelRows = 4096;
/// Entries (rows × right-hand sides) of a PCG solve.
inline constexpr long kParallelPcgEntries = 8192;
/// Terms of a deterministic sum (par::det_sum).
inline constexpr long kParallelSumTerms = 8192;

}  // namespace capsflow::shell
