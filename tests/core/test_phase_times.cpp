// PhaseTimes and Stopwatch: wall and CPU seconds per phase. CPU seconds are the process's (all
// threads), so CPU/wall tells how many threads a phase kept busy. The bounds below hold on a
// loaded machine too: a descheduled thread loses CPU time, never gains it.
#include <gtest/gtest.h>
#include <omp.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "capsflow/core/phase_times.hpp"

namespace capsflow {
namespace {

// About `n` dependent floating-point operations that the compiler cannot drop.
double busy(long n, double seed) {
  double x = seed;
  for (long i = 0; i < n; ++i) x = std::sqrt(x * x + 1e-3);
  return x;
}

TEST(PhaseTimes, ASleepingPhaseTakesWallTimeButNoCpu) {
  PhaseTimes t;
  Stopwatch w;
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  w.lap(t, Phase::Load);
  EXPECT_GE(t[Phase::Load], 0.19);                    // sleep_for sleeps at least that long
  EXPECT_LT(t.cpu(Phase::Load), 0.1 * t[Phase::Load]);  // a sleeping thread uses (almost) no CPU
}

TEST(PhaseTimes, ABusyPhaseOnOneThreadUsesAtMostItsWallTime) {
  PhaseTimes t;
  Stopwatch w;
  volatile double sink = busy(20'000'000, 1.0);
  (void)sink;
  w.lap(t, Phase::Wall);
  EXPECT_GT(t.cpu(Phase::Wall), 0.0);
  // One running thread: CPU ≤ wall, up to the two clocks' resolutions (1 ms is generous).
  EXPECT_LE(t.cpu(Phase::Wall), t[Phase::Wall] + 1e-3);
  // Laps go to their own phase only, and += adds both kinds.
  EXPECT_EQ(t[Phase::BieFar], 0.0);
  EXPECT_EQ(t.cpu(Phase::BieFar), 0.0);
  PhaseTimes sum = t;
  sum += t;
  EXPECT_EQ(sum.cpu(Phase::Wall), 2 * t.cpu(Phase::Wall));
  EXPECT_EQ(sum[Phase::Wall], 2 * t[Phase::Wall]);
}

TEST(PhaseTimes, ThreadsOfTheProcessAreCounted) {
  // The same work serially and split over two threads: the CPU seconds of both phases measure
  // that work (the split version at least 70 % of the serial one: the threads' CPU is counted,
  // whatever the load on the machine), while only the serial one is bounded by its wall time.
  PhaseTimes t;
  Stopwatch w;
  volatile double sink = busy(40'000'000, 1.0);
  w.lap(t, Phase::Wall);
  double parts[2] = {0, 0};
#pragma omp parallel for num_threads(2) schedule(static)
  for (int k = 0; k < 2; ++k) parts[k] = busy(20'000'000, 1.0 + k);
  sink = parts[0] + parts[1];
  (void)sink;
  w.lap(t, Phase::BieFar);
  EXPECT_GT(t.cpu(Phase::BieFar), 0.7 * t.cpu(Phase::Wall)) << "wall " << t[Phase::BieFar];
}

}  // namespace
}  // namespace capsflow
