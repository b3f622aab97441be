#pragma once
// The closest approach of a capsule to a channel's wall over a run (docs/channel.md §5): after
// every accepted step the smallest distance from a capsule node to the wall, in wall element sizes
// (ChannelDynamics::wall_gap). The `surface_gap` condition begins when it falls below
// contact.min_gap — the gap down to which the near-singular quadrature between surfaces is
// measured — and ends above twice that; one warning per episode, a stop under time.stop_on.
#include <nlohmann/json.hpp>
#include <optional>

#include "capsflow/core/health/health_monitor.hpp"

namespace capsflow {

class WallGapWatch {
 public:
  explicit WallGapWatch(double min_gap) : min_gap_(min_gap) {}
  // The gap at time t; the event when an episode begins now.
  std::optional<HealthEvent> observe(double t, double gap);
  bool active() const { return active_; }
  // summary.json: the smallest gap over the run and when, the threshold, the episodes.
  nlohmann::json summary() const;
  nlohmann::json state() const;  // restarts: the worst gap so far, the episode in progress
  void set_state(const nlohmann::json& j);

 private:
  double min_gap_;
  double worst_ = -1, t_worst_ = 0;  // worst_ < 0: nothing observed yet
  bool active_ = false;
  long episodes_ = 0;
};

}  // namespace capsflow
