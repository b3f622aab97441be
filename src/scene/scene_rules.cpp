#include "scene_rules.hpp"

#include <fmt/core.h>

#include <cmath>
#include <cstdlib>

#include "key_table.hpp"

namespace capsflow::scene_detail {

void derive(Scene& s) {
  if (s.mesh.shape == MeshShape::Sphere) s.mesh.aspect = 1.0;
  FlowSpec& f = s.flow;
  if (f.ca_s_from_ca_v) f.ca_s = f.ca_v / s.wall.thickness;
  else f.ca_v = f.ca_s * s.wall.thickness;
  if (f.type != FlowType::Linear) {
    f.gradient.setZero();
    if (f.type == FlowType::PlanarHyperbolic) f.gradient.diagonal() << 1, 0, -1;  // v∞ = x1 e1 − x3 e3 (paper Eq. 39)
    if (f.type == FlowType::SimpleShear) f.gradient(0, 1) = 1;                  // v∞ = x2 e1
  }
}

namespace {

// "time.dt: 1e-300 would need 5e300 steps to time.t_end = 5; at most 1e9 are allowed (time.dt ≥ 5e-9)".
void check_count(const TomlReader& r, const std::string& section, const std::string& key, double interval,
                 double t_end, double bound, const std::string& what) {
  const double n = t_end / interval;
  if (!(n > bound)) return;
  // 3 digits: 5e300, not 4.9999999999999997e300; beyond the doubles, "more than 1e308".
  const std::string about =
      std::isfinite(n) ? number_text(std::strtod(fmt::format("{:.3g}", n).c_str(), nullptr)) : "more than 1e308";
  r.fail(section, key,
         fmt::format("{} would need {} {} to time.t_end = {}; at most {} are allowed ({}.{} ≥ {})", number_text(interval),
                     about, what, number_text(t_end), number_text(bound), section, key,
                     number_text(t_end / bound)));
}

}  // namespace

// What several capsules ([layout] count > 1 or [[capsule]] tables) do not do, named by its key.
void check_several_capsules(const TomlReader& r, const Scene& s) {
  const LayoutSpec& l = s.layout;
  if (s.capsules.empty() && l.count > 1 && l.dx == 0 && l.dy == 0 && l.dz == 0)
    r.fail("layout", "count", fmt::format("{} capsules at one place: give their step layout.dx, dy or dz", l.count));
  if (s.capsule_centers().size() < 2) return;
  if (s.fluid.viscosity_ratio != 1.0)
    r.fail("fluid", "viscosity_ratio", "must be 1 with several capsules (the double layer over several surfaces is not "
                                       "implemented)");
  if (s.time.stop_at_steady)
    r.fail("time", "stop_at_steady", "several capsules have no steady-state test: set time.t_end instead");
}

// A channel and its flow go together, with one capsule at λ = 1 (docs/channel.md).
void check_channel(const TomlReader& r, const Scene& s) {
  const bool poiseuille = s.flow.type == FlowType::Poiseuille;
  if (s.channel.active() && !poiseuille) r.fail("flow", "type", "must be \"poiseuille\" with a [channel]");
  if (!s.channel.active() && poiseuille)
    r.fail("channel", "shape", "a Poiseuille flow needs a channel: set channel.shape to \"tube\", \"square_duct\" or \"constricted_duct\"");
  if (s.channel.shape != ChannelKind::ConstrictedDuct) {
    // A constriction's key set away from its default with another shape (a stored scene writes every
    // key with its default: accepted).
    const ChannelSpec d;
    const ChannelSpec& c = s.channel;
    const std::pair<const char*, bool> keys[] = {
        {"constriction_height", c.constriction_height != d.constriction_height},
        {"constriction_width", c.constriction_width != d.constriction_width},
        {"constriction_length", c.constriction_length != d.constriction_length},
        {"constriction_center", c.constriction_center != d.constriction_center},
        {"constriction_taper", c.constriction_taper_auto != d.constriction_taper_auto ||
                                   (!c.constriction_taper_auto && c.constriction_taper != d.constriction_taper)}};
    for (const auto& [key, changed] : keys)
      if (r.has("channel", key) && changed)
        r.fail("channel", key, "is a constricted duct's: set channel.shape = \"constricted_duct\"");
  }
  if (!s.channel.active()) return;
  if (s.capsule_centers().size() > 1)
    r.fail("channel", "shape", "holds one capsule: several capsules in a channel are not implemented");
  if (s.fluid.viscosity_ratio != 1.0)
    r.fail("fluid", "viscosity_ratio", "must be 1 in a channel (the double layer with a channel wall is not implemented)");
}

void check_rules(const TomlReader& r, const Scene& s) {
  const FlowSpec& f = s.flow;
  if (r.has("flow", "ca_v") && r.has("flow", "ca_s")) r.fail("flow", "ca_s", "give either flow.ca_s or flow.ca_v, not both");
  if (f.ca_s_from_ca_v && !capillary_range().contains(f.ca_s)) {  // blamed on the key the user gave
    const bool thickness = !r.has("flow", "ca_v") && r.has("wall", "thickness");
    r.fail(thickness ? "wall" : "flow", thickness ? "thickness" : "ca_v",
           fmt::format("ca_v = {} and thickness = {} give Ca_s = ca_v/thickness = {}, out of range: must be in {} ({})",
                       number_text(f.ca_v), number_text(s.wall.thickness), number_text(f.ca_s),
                       capillary_range().interval(), capillary_range().why));
  }
  if (f.type == FlowType::Linear) {
    if (!r.has("flow", "gradient")) r.fail("flow", "gradient", "required when flow.type = \"linear\"");
  } else if (r.has("flow", "gradient")) {
    r.fail("flow", "gradient", "only used with flow.type = \"linear\"");
  }
  // Counted from t = 0 also on a restart: the bound is on the run, and the check needs no checkpoint.
  const double t_end = s.time.t_end;
  if (!s.time.dt_auto) check_count(r, "time", "dt", s.time.dt, t_end, kMaxSteps, "steps");
  check_count(r, "output", "every", s.output.every, t_end, kMaxOutputs, "outputs");
  check_several_capsules(r, s);
  check_channel(r, s);
  if (s.output.checkpoint_every > 0)
    check_count(r, "output", "checkpoint_every", s.output.checkpoint_every, t_end, kMaxOutputs, "checkpoints");
}

}  // namespace capsflow::scene_detail
