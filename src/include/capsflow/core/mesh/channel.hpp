#pragma once
// The closed surface of a straight channel (docs/channel.md §1): a side wall around the x axis —
// a circular tube of radius R or a square duct of half-width W — from x = −length/2 (the inlet) to
// +length/2 (the outlet), closed by two flat end caps through which the flow enters and leaves.
// The side is a structured extrusion of one cross-section ring (quads split in two), each cap a
// triangulation of the cross-section whose rim is the side's end ring, so the surface is one
// closed P1 mesh with shared vertices and outward normals (CCW seen from outside, types.hpp).
#include <vector>

#include "capsflow/core/named_enum.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

enum class ChannelShape { Tube, SquareDuct };

inline constexpr NameTable<ChannelShape, 2> kChannelShapeNames{
    {{ChannelShape::Tube, "tube"}, {ChannelShape::SquareDuct, "square_duct"}}};
constexpr const auto& name_table(ChannelShape) { return kChannelShapeNames; }

struct ChannelGeometry {
  ChannelShape shape = ChannelShape::Tube;
  double radius = 1;        // tube radius R, or the duct's half-width W
  double length = 10;       // from inlet to outlet along x
  double element_size = 0.1;  // target edge length on the side and the caps
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
// not positive, or an element size above the radius (fewer than 6 elements around).
ChannelMesh make_channel_mesh(const ChannelGeometry& g);

// The cross-section's area (πR² or 4W²) of the exact shape.
double channel_cross_section_area(const ChannelGeometry& g);
// How far (y, z) lies from the axis in the cross-section's own measure — √(y² + z²) in a tube,
// max(|y|, |z|) in a square duct —, so that the wall is where it equals the radius.
double distance_from_axis(const ChannelGeometry& g, double y, double z);

}  // namespace capsflow
