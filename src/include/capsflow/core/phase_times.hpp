#pragma once
// Wall-clock seconds per phase of the right-hand side, accumulated over a run: the one timer of
// capsflow::core (the boundary integral, the right-hand side and the run's timing table all use
// it). Phases are fixed, so adding a phase is one line here and one name in kPhaseNames.
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
  Other,       // flow, updates, volume correction
  Count
};
inline constexpr std::array<const char*, static_cast<std::size_t>(Phase::Count)> kPhaseNames = {
    "wall_rotations_and_forces", "load_mass_solve", "bie_sources", "bie_far", "bie_near", "bie_verify", "other"};

class PhaseTimes {
 public:
  double& operator[](Phase p) { return s_[static_cast<std::size_t>(p)]; }
  double operator[](Phase p) const { return s_[static_cast<std::size_t>(p)]; }
  PhaseTimes& operator+=(const PhaseTimes& o) {
    for (std::size_t i = 0; i < s_.size(); ++i) s_[i] += o.s_[i];
    return *this;
  }

 private:
  std::array<double, static_cast<std::size_t>(Phase::Count)> s_{};
};

// Seconds since construction; `lap(times, phase)` adds them to a phase and restarts.
class Stopwatch {
 public:
  using Clock = std::chrono::steady_clock;
  double seconds() const { return std::chrono::duration<double>(Clock::now() - t0_).count(); }
  void restart() { t0_ = Clock::now(); }
  void lap(PhaseTimes& times, Phase p) {
    const Clock::time_point now = Clock::now();
    times[p] += std::chrono::duration<double>(now - t0_).count();
    t0_ = now;
  }

 private:
  Clock::time_point t0_ = Clock::now();
};

}  // namespace capsflow
