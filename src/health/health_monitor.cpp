#include "capsflow/core/health/health_monitor.hpp"

#include <algorithm>
#include <fmt/core.h>

#include "capsflow/core/rhs/wall_factory.hpp"
#include "capsflow/core/geometry/taylor_deformation.hpp"
#include "capsflow/core/mesh/stats.hpp"

namespace capsflow {

namespace {
// Grid-scale oscillation |U c|/h (geometry/surface_roughness.hpp) that means buckling or folds the
// mesh does not resolve. Measured (docs/health-monitors.md): 0.0024 on a level-4 icosphere, up
// to 0.004 on the GSMB α = 3 % sphere in hyperbolic flow (smooth to γ̇t = 0.6); the NH membrane
// at Ca_s = 0.005 passes 0.022 at γ̇t = 0.12 and 0.09 at 0.16, when its D13 leaves the GSMB value
// by 2 %; a fold of wavelength 16 h and amplitude 0.6 h gives 0.018. 0.03, or 4× the reference
// mesh's own level for irregular user meshes, separates them; an episode ends below half of it.
constexpr double kOscillationThreshold = 0.03, kOscillationReferenceFactor = 4.0;
// Facets whose smallest angle falls below 10° (or half the reference mesh's smallest, if that is
// lower) or whose aspect ratio exceeds 8: the near-singular quadrature and the MITC3 element are
// validated on facets far from this (docs/boundary-integral.md, docs/shell.md).
constexpr double kMinAngleDeg = 10.0, kMaxAspect = 8.0;
// No equilibrium: the largest principal stretch above 3 and the capsule's length (the largest semi-axis
// of its inertia ellipsoid, a global measure that local folds do not jolt) still growing by 3 % per
// unit γ̇t. The paper's steady cases stay below a stretch of 2; strain-softening NH in shear at high Ca
// elongates without bound (Barthès-Biesel, Diaz & Dhenin 2002).
constexpr double kNoEquilibriumStretch = 3.0, kNoEquilibriumGrowth = 0.03;
// ... unless the growth is slowing down towards an equilibrium in sight: the increments of the length
// over the last two half units, d1 then d2 < d1, extrapolated as a geometric series, end below this
// multiple of the current length (the stretch histories that set it: docs/health-monitors.md §4.1).
constexpr double kEquilibriumInSight = 2.0;
// A membrane's grid-scale oscillation is buckling only where the wall is compressed: the facets
// within this many reference edge lengths of the worst node are searched for a negative tension.
// Elsewhere (e.g. the tips of a capsule at Ca_s = 10, under tension, a few elements across) it is
// curvature the mesh does not resolve.
constexpr double kCompressionProbeEdges = 3.0;

std::string where(const Vec3& p) { return fmt::format("({:.2f}, {:.2f}, {:.2f})", p.x(), p.y(), p.z()); }
// The capsule's length at time tau, linear between the stored samples (tau within their span).
double length_at(const std::vector<std::pair<double, double>>& h, double tau) {
  for (size_t i = 1; i < h.size(); ++i)
    if (h[i].first >= tau) {
      const auto& [ta, la] = h[i - 1];
      const auto& [tb, lb] = h[i];
      return tb > ta ? la + (lb - la) * (tau - ta) / (tb - ta) : lb;
    }
  return h.back().second;
}
}  // namespace

HealthMonitor::HealthMonitor(const Scene& scene, const SurfaceMesh& reference)
    : ref_(reference),
      bending_(scene.wall.model == WallModel::Gsmb),
      law_(scene_law(scene)),
      meter_(reference.triangles, reference.num_nodes()),
      probe_radius_(kCompressionProbeEdges * mesh_stats(reference).edge_mean) {
  const SurfaceRoughness r0 = meter_.measure(reference.vertices);
  oscillation_threshold_ = std::max(kOscillationThreshold, kOscillationReferenceFactor * r0.grid_oscillation_p99);
  const ElementQuality q0 = element_quality(reference, reference.vertices);
  worst_min_angle_ = q0.min_angle_deg;
  // A reference mesh that is already worse (an a/b = 6 spheroid has 9.9° facets) is judged
  // against itself: half its smallest angle, twice its aspect ratio.
  min_angle_threshold_ = std::min(kMinAngleDeg, 0.5 * q0.min_angle_deg);
  aspect_threshold_ = std::max(kMaxAspect, 2 * q0.max_aspect_ratio);
}

std::optional<HealthEvent> HealthMonitor::update(HealthCondition c, bool on, bool off, double t, const std::string& message) {
  bool& a = active_[static_cast<size_t>(c)];
  if (!a && on) {
    a = true;
    HealthEvent e{c, t, message};
    events_.push_back(e);
    return e;
  }
  if (a && off) a = false;
  return std::nullopt;
}

std::vector<HealthEvent> HealthMonitor::observe(double t, const Points& x, const SolverEffort& effort) {
  HealthSample& s = last_;
  s.t = t;
  s.roughness = meter_.measure(x);
  s.quality = element_quality(ref_, x);
  s.compression = membrane_compression(ref_, x, law_, s.roughness.worst_position, probe_radius_);
  s.effort = effort;

  worst_angle_ = std::max(worst_angle_, s.roughness.facet_angle_max);
  worst_oscillation_ = std::max(worst_oscillation_, s.roughness.grid_oscillation_p99);
  worst_compressed_fraction_ = std::max(worst_compressed_fraction_, s.compression.compressed_area_fraction);
  worst_tension_ = std::min(worst_tension_, s.compression.min_tension);
  worst_min_angle_ = std::min(worst_min_angle_, s.quality.min_angle_deg);
  worst_aspect_ = std::max(worst_aspect_, s.quality.max_aspect_ratio);
  worst_stretch_ratio_ = std::max(worst_stretch_ratio_, s.quality.max_stretch_ratio);
  worst_stretch_ = std::max(worst_stretch_, s.quality.max_stretch);
  worst_newton_ = std::max(worst_newton_, effort.newton_per_evaluation);
  worst_rotation_cg_ = std::max(worst_rotation_cg_, effort.rotation_cg_per_evaluation);
  worst_mass_cg_ = std::max(worst_mass_cg_, effort.mass_cg_per_evaluation);

  std::vector<HealthEvent> out;
  auto add = [&out](std::optional<HealthEvent> e) {
    if (e) out.push_back(std::move(*e));
  };

  const MembraneCompression& c = s.compression;
  const SurfaceRoughness& r = s.roughness;
  const bool osc_on = r.grid_oscillation_p99 > oscillation_threshold_;
  const bool osc_off = r.grid_oscillation_p99 < 0.5 * oscillation_threshold_;
  // A membrane oscillating where it is compressed buckles; anywhere else, and on a wall with
  // bending stiffness, the shape varies faster than the mesh resolves.
  const bool compressed_there = c.min_tension_near_probe < 0;
  if (!bending_)
    add(update(HealthCondition::MeshScaleBuckling, osc_on && compressed_there, osc_off, t,
               fmt::format("the membrane wall is under compression ({:.0f} % of its area, principal tension down to {:.2g} G_s) "
                           "and is buckling at the mesh scale near {} since γ̇t = {:.3g} (grid-scale oscillation {:.3f} > {:.3f}, "
                           "facet angles up to {:.0f}°); results after this time depend on the mesh: a wall without bending "
                           "stiffness cannot carry compression (use wall.model = \"gsmb\" with a thickness)",
                           100 * c.compressed_area_fraction, c.min_tension, where(r.worst_position), t, r.grid_oscillation_p99,
                           oscillation_threshold_, r.facet_angle_max)));
  const std::string unresolved_what =
      bending_ ? "the wall folds at the scale of the mesh"
               : "the membrane's shape varies at the scale of the mesh where it is in tension (no compression within "
                 "3 elements)";
  add(update(HealthCondition::UnresolvedFolds, osc_on && (bending_ || !compressed_there), osc_off, t,
             fmt::format("{} near {} since γ̇t = {:.3g} (grid-scale oscillation {:.3f} > {:.3f}, facet angles up to {:.0f}°): "
                         "{} shorter than a few elements, so results after this time depend on the mesh (refine: "
                         "mesh.level + 1 halves h)",
                         unresolved_what, where(r.worst_position), t, r.grid_oscillation_p99, oscillation_threshold_,
                         r.facet_angle_max, bending_ ? "the folds are" : "its curvature varies over lengths")));

  const ElementQuality& q = s.quality;
  add(update(HealthCondition::ElementQuality, q.min_angle_deg < min_angle_threshold_ || q.max_aspect_ratio > aspect_threshold_,
             q.min_angle_deg > 1.5 * min_angle_threshold_ && q.max_aspect_ratio < 0.6 * aspect_threshold_, t,
             fmt::format("facets are degenerating at γ̇t = {:.3g} (smallest angle {:.1f}°, aspect ratio {:.1f}, stretch ratio "
                         "{:.1f}): the mesh cannot follow this deformation accurately (refine the mesh, or the state is "
                         "beyond what the wall model describes)",
                         t, q.min_angle_deg, q.max_aspect_ratio, q.max_stretch_ratio)));

  // No equilibrium: compare with the capsule's length one time unit ago.
  const double length = inertia_ellipsoid(SurfaceMesh{x, ref_.triangles}).semi_axes.maxCoeff();
  length_history_.emplace_back(t, length);
  while (length_history_.size() > 2 && length_history_[1].first <= t - 1.0) length_history_.erase(length_history_.begin());
  const auto& [t0, l0] = length_history_.front();
  bool growing = t - t0 >= 1.0 - 1e-9 && length > (1 + kNoEquilibriumGrowth * (t - t0)) * l0;
  if (growing) {
    const double d1 = length_at(length_history_, t - 0.5) - length_at(length_history_, t - 1.0);
    const double d2 = length - length_at(length_history_, t - 0.5);
    const double r = d2 / d1;
    if (d1 > 0 && r < 1 && length + d2 * r / (1 - r) < kEquilibriumInSight * length) growing = false;
  }
  add(update(HealthCondition::NoEquilibrium, q.max_stretch > kNoEquilibriumStretch && growing, !growing, t,
             fmt::format("the capsule keeps elongating at γ̇t = {:.3g}: largest stretch {:.2f}, length up {:.1f} % since γ̇t = "
                         "{:.3g} and not slowing down; no equilibrium shape is in sight (a strain-softening law at high Ca "
                         "has none)",
                         t, q.max_stretch, 100 * (length / l0 - 1), t0)));
  return out;
}

std::vector<std::pair<std::string, double>> HealthMonitor::columns() const {
  const HealthSample& s = last_;
  return {{"facet_angle_max", s.roughness.facet_angle_max},
          {"facet_angle_p99", s.roughness.facet_angle_p99},
          {"grid_oscillation", s.roughness.grid_oscillation_p99},
          {"compressed_area_fraction", s.compression.compressed_area_fraction},
          {"min_tension", s.compression.min_tension},
          {"min_facet_angle", s.quality.min_angle_deg},
          {"max_aspect_ratio", s.quality.max_aspect_ratio},
          {"max_stretch", s.quality.max_stretch},
          {"max_stretch_ratio", s.quality.max_stretch_ratio},
          {"newton_per_eval", s.effort.newton_per_evaluation},
          {"rotation_cg_per_eval", s.effort.rotation_cg_per_evaluation},
          {"mass_cg_per_eval", s.effort.mass_cg_per_evaluation}};
}

nlohmann::json HealthMonitor::summary() const {
  nlohmann::json ev = nlohmann::json::array();
  for (const auto& e : events_) ev.push_back({{"condition", to_string(e.condition)}, {"t", e.t}, {"message", e.message}});
  return {{"facet_angle_max", worst_angle_},
          {"grid_oscillation_max", worst_oscillation_},
          {"grid_oscillation_threshold", oscillation_threshold_},
          {"compressed_area_fraction_max", worst_compressed_fraction_},
          {"min_tension", worst_tension_},
          {"min_facet_angle", worst_min_angle_},
          {"max_aspect_ratio", worst_aspect_},
          {"max_stretch", worst_stretch_},
          {"max_stretch_ratio", worst_stretch_ratio_},
          {"newton_per_eval_max", worst_newton_},
          {"rotation_cg_per_eval_max", worst_rotation_cg_},
          {"mass_cg_per_eval_max", worst_mass_cg_},
          {"warnings", ev}};
}

std::string HealthMonitor::status() const {
  std::string s;
  for (const auto& [c, name] : kHealthConditionNames)
    if (active(c)) s += (s.empty() ? "" : ",") + std::string(name);
  return s.empty() ? "ok" : s;
}

nlohmann::json HealthMonitor::state() const {
  nlohmann::json j = summary();
  nlohmann::json act = nlohmann::json::array();
  for (bool a : active_) act.push_back(a);
  nlohmann::json hist = nlohmann::json::array();
  for (const auto& [t, l] : length_history_) hist.push_back({t, l});
  j["active"] = act;
  j["length_history"] = hist;
  return j;
}

void HealthMonitor::set_state(const nlohmann::json& j) {
  worst_angle_ = j.at("facet_angle_max");
  worst_oscillation_ = j.at("grid_oscillation_max");
  worst_compressed_fraction_ = j.at("compressed_area_fraction_max");
  worst_tension_ = j.at("min_tension");
  worst_min_angle_ = j.at("min_facet_angle");
  worst_aspect_ = j.at("max_aspect_ratio");
  worst_stretch_ = j.at("max_stretch");
  worst_stretch_ratio_ = j.at("max_stretch_ratio");
  worst_newton_ = j.at("newton_per_eval_max");
  worst_rotation_cg_ = j.at("rotation_cg_per_eval_max");
  worst_mass_cg_ = j.at("mass_cg_per_eval_max");
  events_.clear();
  for (const auto& e : j.at("warnings"))
    events_.push_back({*from_string<HealthCondition>(e.at("condition").get<std::string>()), e.at("t"), e.at("message")});
  for (size_t i = 0; i < active_.size() && i < j.at("active").size(); ++i) active_[i] = j.at("active")[i];
  length_history_.clear();
  // Older checkpoints kept the largest stretch instead (docs/health-monitors.md §4.1): the history starts afresh.
  if (j.contains("length_history"))
    for (const auto& p : j.at("length_history")) length_history_.emplace_back(p[0].get<double>(), p[1].get<double>());
}

}  // namespace capsflow
