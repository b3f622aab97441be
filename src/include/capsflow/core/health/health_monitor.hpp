#pragma once
// Health monitors of a run (docs/health-monitors.md): cheap O(N) measures of the wall's state,
// taken after every accepted step (compressive tension, facet angles, grid-scale oscillation,
// element quality, inner-solver effort), recorded at output times (timeseries.csv) and as the worst over
// the run (summary.json), and turned into one warning per episode of a named condition:
//   mesh_scale_buckling  a wall without bending stiffness oscillates at the two-element wavelength
//                        where it is compressed
//   unresolved_folds     a wall with bending stiffness does (its folds are shorter than the mesh
//                        resolves), or a membrane does where it is in tension (unresolved curvature)
//   element_quality      facets degenerate (smallest angle, aspect ratio)
//   no_equilibrium       the largest stretch keeps growing past kNoEquilibriumStretch
// Thresholds are measured, with their reasons, in health_monitor.cpp.
#include <optional>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>

#include "capsflow/core/health/health_conditions.hpp"
#include "capsflow/core/geometry/element_quality.hpp"
#include "capsflow/core/geometry/surface_roughness.hpp"
#include "capsflow/core/health/membrane_compression.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

// Inner-solver effort per right-hand-side evaluation over an interval.
struct SolverEffort {
  double newton_per_evaluation = 0, rotation_cg_per_evaluation = 0, mass_cg_per_evaluation = 0;
};

struct HealthSample {
  double t = 0;
  SurfaceRoughness roughness;
  MembraneCompression compression;
  ElementQuality quality;
  SolverEffort effort;
};

// A condition that has just begun an episode.
struct HealthEvent {
  HealthCondition condition;
  double t = 0;
  std::string message;  // one line: what, where, since when, what it means, the remedy
};

class HealthMonitor {
 public:
  HealthMonitor(const Scene& scene, const SurfaceMesh& reference);
  // Measure the state x at time t; returns the conditions whose episode begins now.
  std::vector<HealthEvent> observe(double t, const Points& x, const SolverEffort& effort);
  const HealthSample& last() const { return last_; }
  bool active(HealthCondition c) const { return active_[static_cast<size_t>(c)]; }
  // The wall oscillates at the two-element wavelength (mesh_scale_buckling or unresolved_folds).
  bool folding() const { return active(HealthCondition::MeshScaleBuckling) || active(HealthCondition::UnresolvedFolds); }
  // The timeseries columns of the last sample (name, value), in a fixed order.
  std::vector<std::pair<std::string, double>> columns() const;
  // Worst values over the run and every event so far.
  nlohmann::json summary() const;
  // A short status for the progress line: "ok" or the active conditions.
  std::string status() const;
  // Restart: everything observe() accumulates.
  nlohmann::json state() const;
  void set_state(const nlohmann::json& j);

 private:
  std::optional<HealthEvent> update(HealthCondition c, bool on, bool off, double t, const std::string& message);

  SurfaceMesh ref_;
  bool bending_;  // the wall has bending stiffness (GSMB)
  shell::MembraneLaw law_;
  RoughnessMeter meter_;
  double probe_radius_;  // of the compression test at the worst grid-scale oscillation
  double oscillation_threshold_, min_angle_threshold_, aspect_threshold_;
  HealthSample last_;
  std::array<bool, kHealthConditionNames.size()> active_{};
  std::vector<std::pair<double, double>> length_history_;  // (t, largest semi-axis of the inertia ellipsoid)
  // Worst over the run.
  double worst_angle_ = 0, worst_oscillation_ = 0, worst_compressed_fraction_ = 0, worst_tension_ = 0;
  double worst_min_angle_ = 60, worst_aspect_ = 1, worst_stretch_ratio_ = 1, worst_stretch_ = 1;
  double worst_newton_ = 0, worst_rotation_cg_ = 0, worst_mass_cg_ = 0;
  std::vector<HealthEvent> events_;
};

}  // namespace capsflow
