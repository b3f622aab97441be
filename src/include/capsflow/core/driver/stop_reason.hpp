#pragma once
// Why a run stopped: summary.json's `stop_reason`, the process exit code and what a study makes of
// a finished variant folder (docs/scene-and-output.md §3). One table gives each reason its
// spelling and exit code; a stop on a health monitor (time.stop_on) is spelled by its condition
// (health/health_conditions.hpp), so each spelling is written once.
//
// summary.json writes `name` or `name: detail` (solver_failure and the rejected-step no_progress
// carry one line of detail). Readers parse it back with StopReason::parse.
#include <array>
#include <optional>
#include <string>

#include "capsflow/core/health/health_conditions.hpp"

namespace capsflow {

enum class StopKind {
  TEnd,           // t_end reached
  Steady,         // steady state detected (time.stop_at_steady)
  Outlet,         // the capsule came within reach of a lab-frame channel's outlet (a constriction passed)
  Interrupted,    // SIGINT/SIGTERM or a caller's stop request: checkpoint written, can continue
  BlowUp,         // a step failed the run-health checks; the last healthy state is kept
  SolverFailure,  // an inner solve of the right-hand side failed
  NoProgress,     // the step does not advance t, or too many rejected steps in a row
  Health,         // a health monitor's condition listed in time.stop_on
};

struct StopKindInfo {
  StopKind kind;
  const char* name;  // nullptr for Health: spelled by its condition
  int exit_code;     // 0: the run did what it was asked; 3: its last state is not trustworthy; 130: interrupted
};
inline constexpr std::array<StopKindInfo, 8> kStopKinds{{{StopKind::TEnd, "t_end", 0},
                                                         {StopKind::Steady, "steady", 0},
                                                         {StopKind::Outlet, "outlet", 0},
                                                         {StopKind::Interrupted, "interrupted", 130},
                                                         {StopKind::BlowUp, "blow_up", 3},
                                                         {StopKind::SolverFailure, "solver_failure", 3},
                                                         {StopKind::NoProgress, "no_progress", 3},
                                                         {StopKind::Health, nullptr, 3}}};

class StopReason {
 public:
  explicit StopReason(StopKind kind = StopKind::TEnd, std::string detail = {});
  static StopReason health(HealthCondition condition, std::string detail = {});
  // summary.json's spelling back to a reason; nullopt for a name no table knows.
  static std::optional<StopReason> parse(const std::string& text);

  StopKind kind() const { return kind_; }
  std::optional<HealthCondition> condition() const { return condition_; }  // Health only
  const std::string& detail() const { return detail_; }
  std::string name() const;       // "blow_up", "no_equilibrium", …
  std::string to_string() const;  // name, or "name: detail" (summary.json)
  int exit_code() const;
  bool finished() const { return exit_code() == 0; }  // t_end or steady: the run is complete

 private:
  StopKind kind_;
  std::optional<HealthCondition> condition_;
  std::string detail_;
};

}  // namespace capsflow
