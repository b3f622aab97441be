#pragma once
// Deterministic OpenMP helpers: reductions are summed over fixed-size chunks (independent of the
// thread count), then the chunk partials are added serially, so results are bit-identical for any
// number of threads. TeamBarrier: a barrier for the threads of one OpenMP team that spins briefly
// before it sleeps.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <climits>
#include <cmath>
#include <thread>
#include <vector>
#if defined(__linux__)
#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include "capsflow/shell/parallel_thresholds.hpp"

namespace capsflow::shell::par {

/// Terms per chunk: fixes the summation order (changing it changes the last bits of results).
inline constexpr long kChunk = 4096;

/// sum_i f(i) for i in [0, n), deterministic. `partial` is scratch (resized if needed).
template <class F>
double det_sum(long n, std::vector<double>& partial, F&& f) {
  const long nc = (n + kChunk - 1) / kChunk;
  if (static_cast<long>(partial.size()) < nc) partial.resize(nc);
#pragma omp parallel for schedule(static) if (n > kParallelSumTerms)
  for (long c = 0; c < nc; ++c) {
    double s = 0;
    const long e = std::min(n, (c + 1) * kChunk);
    for (long i = c * kChunk; i < e; ++i) s += f(i);
    partial[c] = s;
  }
  double s = 0;
  for (long c = 0; c < nc; ++c) s += partial[c];
  return s;
}

/// a·b + c rounded once where the hardware has a fused multiply-add, else a·b + c: written out so
/// that the same source gives the same bits on every path of a kernel, whichever multiply-adds the
/// compiler would have fused on its own (-ffp-contract=fast, GCC's default).
inline double fmadd(double a, double b, double c) {
#if defined(__FP_FAST_FMA)
  return std::fma(a, b, c);
#else
  return a * b + c;
#endif
}

/// Barrier of the threads of one OpenMP team (construct it before the parallel region, zeroed;
/// every thread calls wait(omp_get_num_threads())). A waiting thread spins up to kBarrierSpin, then
/// sleeps on a futex until the last thread arrives. OpenMP's own barrier under
/// OMP_WAIT_POLICY=passive (capsflow's policy: docs/scene-and-output.md §1.1) puts the first thread
/// to sleep at once, so every barrier costs a wake-up (tens of µs on a virtual machine) — more than
/// a PCG iteration at 2 562 nodes. Spinning only briefly keeps what passive buys on a shared
/// machine: a thread whose partner lost its core gives the core back after kBarrierSpin.
class TeamBarrier {
 public:
  /// Long enough to cover the wake-up of a sleeping worker at the start of a team (so the
  /// master's first wait does not fall asleep too, which would cost a second wake-up), short
  /// enough to bound what a thread whose partner was descheduled wastes.
  static constexpr std::chrono::microseconds kBarrierSpin{100};
  /// After a wait that had to sleep (the partner did not run: a loaded machine), the next waits of
  /// this barrier spin 8 times less, down to this; a wait that ends while spinning restores kBarrierSpin.
  static constexpr std::chrono::microseconds kBarrierMinSpin{5};

  void wait(int team_size) {
    if (team_size <= 1) return;
    const int gen = generation_.load(std::memory_order_acquire);
    if (arrived_.fetch_add(1, std::memory_order_acq_rel) == team_size - 1) {
      arrived_.store(0, std::memory_order_relaxed);
      generation_.store(gen + 1, std::memory_order_seq_cst);  // releases the reset of arrived_ too
      if (sleepers_.load(std::memory_order_seq_cst) > 0) wake();
      return;
    }
    const auto start = std::chrono::steady_clock::now();
    const std::chrono::microseconds budget{spin_us_.load(std::memory_order_relaxed)};
    for (int k = 1;; ++k) {
      if (generation_.load(std::memory_order_acquire) != gen) {
        if (budget < kBarrierSpin) spin_us_.store(static_cast<int>(kBarrierSpin.count()), std::memory_order_relaxed);
        return;
      }
      pause();
      if (k % 64 == 0 && std::chrono::steady_clock::now() - start > budget) break;
    }
    spin_us_.store(static_cast<int>(std::max(kBarrierMinSpin, budget / 8).count()), std::memory_order_relaxed);
    // Dekker pair with the last thread: it stores the generation, then reads sleepers_; we add to
    // sleepers_, then read the generation (both sequentially consistent), so either it sees us
    // and wakes us, or we see the new generation and do not sleep.
    sleepers_.fetch_add(1, std::memory_order_seq_cst);
    while (generation_.load(std::memory_order_seq_cst) == gen) sleep(gen);
    sleepers_.fetch_sub(1, std::memory_order_seq_cst);
  }

 private:
  static void pause() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
  // Sleeps while generation_ == gen (returns at once if it has changed: the futex checks it).
  void sleep(int gen) {
#if defined(__linux__)
    syscall(SYS_futex, reinterpret_cast<int*>(&generation_), FUTEX_WAIT_PRIVATE, gen, nullptr, nullptr, 0);
#else
    (void)gen;
    std::this_thread::yield();
#endif
  }
  void wake() {
#if defined(__linux__)
    syscall(SYS_futex, reinterpret_cast<int*>(&generation_), FUTEX_WAKE_PRIVATE, INT_MAX, nullptr, nullptr, 0);
#endif
  }
  static_assert(sizeof(std::atomic<int>) == sizeof(int), "the futex word is the atomic's int");
  alignas(64) std::atomic<int> arrived_{0};
  alignas(64) std::atomic<int> generation_{0};
  alignas(64) std::atomic<int> sleepers_{0};
  std::atomic<int> spin_us_{static_cast<int>(kBarrierSpin.count())};  // the spin budget, µs
};

/// [begin, end) of the items of thread `tid` of `team` when n items are split into equal
/// contiguous ranges.
inline void thread_range(long n, int tid, int team, long& begin, long& end) {
  begin = n * tid / team;
  end = n * (tid + 1) / team;
}

inline double dot(long n, const double* a, const double* b, std::vector<double>& partial) {
  return det_sum(n, partial, [&](long i) { return a[i] * b[i]; });
}

}  // namespace capsflow::shell::par
