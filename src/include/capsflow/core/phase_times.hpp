#pragma once
// Wall-clock and CPU seconds per phase of the right-hand side, accumulated over a run: the one
// timer of capsflow::core (the boundary integral, the right-hand side and the run's timing table
// all use it). Phases are fixed, so adding a phase is one line here and one name in kPhaseNames.
//
// CPU seconds are the whole process's (all threads): over a phase, CPU/wall is the number of
// threads that were busy on average, i.e. how parallel the phase is. capsflow runs OpenMP with
// OMP_WAIT_POLICY=passive (docs/scene-and-output.md §1.1), so idle threads sleep instead of
// spinning and do not count.
#include <time.h>

#include <array>
#include <chrono>
#include <cstddef>

namespace capsflow {

enum class Phase : std::size_t {
  Wall,        // rotation solve + internal forces R_s (shell)
  Load,        // M q = R_s (shell::LoadRecovery)
  BieSources,  // quadrature points and strengths (far-field sources, near-field rules)
  BieFar,      // far field: FMM (setup + evaluation) or direct summation
  BieNear,     // exact local integrals replacing the far field near each node
  BieVerify,   // direct re-summation of the far field to check it (fluid.verify_every)
  BieSecondKind,  // viscosity ratio λ ≠ 1: the double layer's set-up and the deflated GMRES solve
  Other,       // flow, updates, volume correction
  Count
};
inline constexpr std::array<const char*, static_cast<std::size_t>(Phase::Count)> kPhaseNames = {
    "wall_rotations_and_forces", "load_mass_solve", "bie_sources", "bie_far", "bie_near", "bie_verify", "bie_second_kind", "other"};

class PhaseTimes {
 public:
  double& operator[](Phase p) { return s_[static_cast<std::size_t>(p)]; }  // wall seconds
  double operator[](Phase p) const { return s_[static_cast<std::size_t>(p)]; }
  double& cpu(Phase p) { return cpu_[static_cast<std::size_t>(p)]; }  // CPU seconds, all threads
  double cpu(Phase p) const { return cpu_[static_cast<std::size_t>(p)]; }
  PhaseTimes& operator+=(const PhaseTimes& o) {
    for (std::size_t i = 0; i < s_.size(); ++i) s_[i] += o.s_[i], cpu_[i] += o.cpu_[i];
    return *this;
  }

 private:
  std::array<double, static_cast<std::size_t>(Phase::Count)> s_{}, cpu_{};
};

// CPU seconds used by the whole process so far (all threads).
inline double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Seconds since construction; `lap(times, phase)` adds them (wall and CPU) to a phase and restarts.
class Stopwatch {
 public:
  using Clock = std::chrono::steady_clock;
  double seconds() const { return std::chrono::duration<double>(Clock::now() - t0_).count(); }
  double cpu_seconds() const { return process_cpu_seconds() - cpu0_; }
  void restart() {
    t0_ = Clock::now();
    cpu0_ = process_cpu_seconds();
  }
  void lap(PhaseTimes& times, Phase p) {
    const Clock::time_point now = Clock::now();
    const double cpu = process_cpu_seconds();
    times[p] += std::chrono::duration<double>(now - t0_).count();
    times.cpu(p) += cpu - cpu0_;
    t0_ = now;
    cpu0_ = cpu;
  }

 private:
  Clock::time_point t0_ = Clock::now();
  double cpu0_ = process_cpu_seconds();
};

}  // namespace capsflow
