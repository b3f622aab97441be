#pragma once
// The closest approach between capsules over a run (several capsules; docs/several-capsules.md):
// after every accepted step the smallest gap between a node of one capsule and an element of
// another, in sizes of that element (bie/cross_near_field.hpp; none beyond 3 sizes), with where
// and when. The `surface_gap` condition begins when it falls below contact.min_gap — the gap down
// to which the near-singular quadrature between surfaces is measured — and ends above twice that;
// one warning per episode, a stop under time.stop_on.
#include <nlohmann/json.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "capsflow/core/bie/cross_near_field.hpp"
#include "capsflow/core/geometry/surface_set.hpp"
#include "capsflow/core/health/health_monitor.hpp"

namespace capsflow {

class SurfaceGapWatch {
 public:
  SurfaceGapWatch(double min_gap, std::vector<SurfacePart> parts) : min_gap_(min_gap), parts_(std::move(parts)) {}
  // The state's closest approach at time t; the event when an episode begins now.
  std::optional<HealthEvent> observe(double t, const SurfaceGap& closest);
  bool active() const { return active_; }
  // timeseries.csv: surface_gap (element sizes; inf beyond 3) and the two capsules (1-based; 0: none).
  std::vector<std::pair<std::string, double>> columns() const;
  // summary.json: the smallest gap over the run, when and between which capsules, the episodes.
  nlohmann::json summary() const;
  nlohmann::json state() const;  // restarts
  void set_state(const nlohmann::json& j);

 private:
  double min_gap_;
  std::vector<SurfacePart> parts_;
  SurfaceGap last_, worst_;
  double t_worst_ = 0;
  bool active_ = false;
  long episodes_ = 0;
};

}  // namespace capsflow
