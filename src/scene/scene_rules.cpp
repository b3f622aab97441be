#include "scene_rules.hpp"

#include <fmt/core.h>

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
  if (s.time.scheme_auto) s.time.scheme = s.wall.model == WallModel::Gsmb ? TimeScheme::Rkc : TimeScheme::Heun;
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
}

}  // namespace capsflow::scene_detail
