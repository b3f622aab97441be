#pragma once
// The sizes below which a loop of capsflow::shell runs on one thread: an OpenMP team costs a fork
// and a barrier (with OMP_WAIT_POLICY=passive, a futex wake-up per thread), which a short loop does
// not repay. They never change a result: every parallel loop writes disjoint entries or sums in
// fixed chunks (parallel.hpp), so the output is bit-identical on or off the team.
//
// Measurement: none chose these values. They were set when the loops were written (session 1, on
// a machine shared by several builds); the only related measurement is perf/shell/RESULTS.md §1:
// at 5 120 elements one wall stage took as long on 1 thread as on 2. How to choose them: on a
// quiet machine, time each loop family at n = 2^8 … 2^16 with OMP_NUM_THREADS=1 and 2 and
// OMP_WAIT_POLICY=passive (the setting capsflow runs with), medians of ≥ 20 calls; the threshold is
// the smallest n at which 2 threads are faster. docs/shell.md §2.7 lists the loops.
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
