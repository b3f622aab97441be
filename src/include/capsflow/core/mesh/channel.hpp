#pragma once
// The closed surface of a channel along x (docs/channel.md §1): a side wall around the x axis —
// a circular tube of radius R, a square duct of half-width W, or a constricted duct: that square
// duct narrowed over a short length to a rectangle of half-height H_c (along y) and half-width
// W_c (along z), reached by straight tapers — from x = −length/2 (the inlet) to +length/2 (the
// outlet), closed by two flat end caps through which the flow enters and leaves.
// The side is a structured extrusion of one cross-section ring (quads split in two; in a
// constriction each station's ring scaled along y and z), each cap a triangulation of the
// cross-section whose rim is the side's end ring, so the surface is one closed P1 mesh with
// shared vertices and outward normals (CCW seen from outside, types.hpp).
#include <vector>

#include "capsflow/core/named_enum.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

enum class ChannelShape { Tube, SquareDuct, ConstrictedDuct };

inline constexpr NameTable<ChannelShape, 3> kChannelShapeNames{
    {{ChannelShape::Tube, "tube"}, {ChannelShape::SquareDuct, "square_duct"}, {ChannelShape::ConstrictedDuct, "constricted_duct"}}};
constexpr const auto& name_table(ChannelShape) { return kChannelShapeNames; }

struct ChannelGeometry {
  ChannelShape shape = ChannelShape::Tube;
  double radius = 1;        // tube radius R, or the duct's half-width W
  double length = 10;       // from inlet to outlet along x
  double element_size = 0.1;  // target edge length on the side and the caps
  // A constricted duct's narrow part: half-height (y) and half-width (z), its length at those
  // sizes, centred at x = constriction_center, and the length of each straight taper to it.
  double constriction_height = 0.5;
  double constriction_width = 1;
  double constriction_length = 1;
  double constriction_center = 0;
  double constriction_taper = 0.1;
  bool straight() const { return shape != ChannelShape::ConstrictedDuct; }
};

// Where a node of the channel lies: on the side wall (the caps' rims included — the wall's
// velocity there is zero), or inside the inlet or outlet cap.
enum class ChannelRegion : unsigned char { Side, Inlet, Outlet };

struct ChannelMesh {
  SurfaceMesh mesh;
  std::vector<ChannelRegion> node_region;  // one per node
  ChannelGeometry geometry;
};

// Throws std::invalid_argument naming the quantity for a radius, length or element size that is
// not positive, or an element size above the radius (fewer than 6 elements around); for a
// constriction, sizes not in (0, radius], a negative taper, or a narrow part and tapers that do
// not fit between the caps.
ChannelMesh make_channel_mesh(const ChannelGeometry& g);

// The cross-section's area (πR² or 4W²) of the exact shape at the inlet and outlet.
double channel_cross_section_area(const ChannelGeometry& g);
// How far (y, z) lies from the axis in the inlet cross-section's own measure — √(y² + z²) in a
// tube, max(|y|, |z|) in a duct —, so that the wall there is where it equals the radius.
double distance_from_axis(const ChannelGeometry& g, double y, double z);
// The cross-section's half-sizes (along y, along z) at station x: (radius, radius) but in a
// constriction and its tapers.
Eigen::Vector2d channel_half_sizes(const ChannelGeometry& g, double x);
// How far p lies from the axis relative to the wall at its station: < 1 inside the channel.
double relative_distance_from_axis(const ChannelGeometry& g, const Vec3& p);

}  // namespace capsflow
