// render_xdmf: one surface is one uniform grid per step; several capsules are one spatial
// collection per step whose grids are HyperSlabs of the union's datasets; parts that do not split
// the mesh are refused.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "capsflow/core/io/xdmf.hpp"

namespace capsflow::io {
namespace {

// The message of the std::invalid_argument `f` throws ("" when it throws none).
template <typename F>
std::string refusal(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// One step with a vector and a scalar node field: what every output step holds.
const std::vector<XdmfStep> kOneStep = {
    {0.25, "/steps/000007", {{"velocity", 3, false}, {"tension", 1, false}}}};

// The layout ParaView has been reading for one surface, written out by hand: Time, the whole
// /mesh/triangles, the step's positions, vector fields [N, 3] and scalars stored 1-D [N].
const std::string kOneSurface =
    "<?xml version=\"1.0\" ?>\n"
    "<!-- capsflow output. Open in ParaView with the \"XDMF Reader\". -->\n"
    "<Xdmf Version=\"3.0\">\n"
    "  <Domain>\n"
    "    <Grid Name=\"capsule\" GridType=\"Collection\" CollectionType=\"Temporal\">\n"
    "      <Grid Name=\"step_000007\" GridType=\"Uniform\">\n"
    "        <Time Value=\"0.25\"/>\n"
    "        <Topology TopologyType=\"Triangle\" NumberOfElements=\"6\">\n"
    "          <DataItem Format=\"HDF\" Dimensions=\"6 3\" NumberType=\"Int\" Precision=\"4\">"
    "run.h5:/mesh/triangles</DataItem>\n"
    "        </Topology>\n"
    "        <Geometry GeometryType=\"XYZ\">\n"
    "          <DataItem Format=\"HDF\" Dimensions=\"5 3\" NumberType=\"Float\" Precision=\"8\">"
    "run.h5:/steps/000007/positions</DataItem>\n"
    "        </Geometry>\n"
    "        <Attribute Name=\"velocity\" AttributeType=\"Vector\" Center=\"Node\">\n"
    "          <DataItem Format=\"HDF\" Dimensions=\"5 3\" NumberType=\"Float\" Precision=\"8\">"
    "run.h5:/steps/000007/velocity</DataItem>\n"
    "        </Attribute>\n"
    "        <Attribute Name=\"tension\" AttributeType=\"Scalar\" Center=\"Node\">\n"
    "          <DataItem Format=\"HDF\" Dimensions=\"5\" NumberType=\"Float\" Precision=\"8\">"
    "run.h5:/steps/000007/tension</DataItem>\n"
    "        </Attribute>\n"
    "      </Grid>\n"
    "    </Grid>\n"
    "  </Domain>\n"
    "</Xdmf>\n";

TEST(Xdmf, OneSurfaceIsOneUniformGridPerStep) {
  // 5 nodes and 6 triangles: different counts, so a node/element mix-up would show.
  EXPECT_EQ(render_xdmf("run.h5", 5, 6, kOneStep), kOneSurface);
  // One part spanning the whole mesh is one surface: the same text, no HyperSlab.
  EXPECT_EQ(render_xdmf("run.h5", 5, 6, kOneStep, MeshParts{{0, 5}, {0, 6}}), kOneSurface);
}

TEST(Xdmf, SeveralCapsulesAreHyperSlabsOfTheUnionRows) {
  // Capsule 1: nodes [0, 4), triangles [0, 4) (a tetrahedron); capsule 2: nodes [4, 10),
  // triangles [4, 12) (an octahedron). A cell field shows that cells use the element rows.
  const MeshParts parts{{0, 4, 10}, {0, 4, 12}};
  const std::vector<XdmfStep> steps = {
      {0.25, "/steps/000007", {{"tension", 1, false}, {"stress", 6, true}}}};
  const std::string xml = render_xdmf("run.h5", 10, 12, steps, parts);
  // The step is a spatial collection holding the time; the capsules are its uniform grids.
  EXPECT_NE(xml.find("      <Grid Name=\"step_000007\" GridType=\"Collection\" "
                     "CollectionType=\"Spatial\">\n        <Time Value=\"0.25\"/>\n"
                     "        <Grid Name=\"capsule 1\" GridType=\"Uniform\">\n"),
            std::string::npos)
      << xml;
  // Capsule 2 in full, written out by hand: 8 triangles from row 4 of local_triangles (all 3
  // columns of the 12×3 dataset), 6 nodes from row 4 of the 10×3 positions, the 1-D scalar in
  // the 3×1 form (start, stride, count), the 12×6 cell field from element row 4.
  const std::string capsule2 =
      "        <Grid Name=\"capsule 2\" GridType=\"Uniform\">\n"
      "          <Topology TopologyType=\"Triangle\" NumberOfElements=\"8\">\n"
      "            <DataItem ItemType=\"HyperSlab\" Dimensions=\"8 3\" Type=\"HyperSlab\">\n"
      "              <DataItem Dimensions=\"3 2\" Format=\"XML\">4 0 1 1 8 3</DataItem>\n"
      "              <DataItem Format=\"HDF\" Dimensions=\"12 3\" NumberType=\"Int\" "
      "Precision=\"4\">run.h5:/mesh/parts/local_triangles</DataItem>\n"
      "            </DataItem>\n"
      "          </Topology>\n"
      "          <Geometry GeometryType=\"XYZ\">\n"
      "            <DataItem ItemType=\"HyperSlab\" Dimensions=\"6 3\" Type=\"HyperSlab\">\n"
      "              <DataItem Dimensions=\"3 2\" Format=\"XML\">4 0 1 1 6 3</DataItem>\n"
      "              <DataItem Format=\"HDF\" Dimensions=\"10 3\" NumberType=\"Float\" "
      "Precision=\"8\">run.h5:/steps/000007/positions</DataItem>\n"
      "            </DataItem>\n"
      "          </Geometry>\n"
      "          <Attribute Name=\"tension\" AttributeType=\"Scalar\" Center=\"Node\">\n"
      "            <DataItem ItemType=\"HyperSlab\" Dimensions=\"6\" Type=\"HyperSlab\">\n"
      "              <DataItem Dimensions=\"3 1\" Format=\"XML\">4 1 6</DataItem>\n"
      "              <DataItem Format=\"HDF\" Dimensions=\"10\" NumberType=\"Float\" "
      "Precision=\"8\">run.h5:/steps/000007/tension</DataItem>\n"
      "            </DataItem>\n"
      "          </Attribute>\n"
      "          <Attribute Name=\"stress\" AttributeType=\"Tensor6\" Center=\"Cell\">\n"
      "            <DataItem ItemType=\"HyperSlab\" Dimensions=\"8 6\" Type=\"HyperSlab\">\n"
      "              <DataItem Dimensions=\"3 2\" Format=\"XML\">4 0 1 1 8 6</DataItem>\n"
      "              <DataItem Format=\"HDF\" Dimensions=\"12 6\" NumberType=\"Float\" "
      "Precision=\"8\">run.h5:/steps/000007/stress</DataItem>\n"
      "            </DataItem>\n"
      "          </Attribute>\n"
      "        </Grid>\n"
      "      </Grid>\n"
      "    </Grid>\n";
  EXPECT_NE(xml.find(capsule2), std::string::npos) << xml;
  // Capsule 1 starts at row 0 of everything: 4 triangles, 4 nodes.
  EXPECT_NE(xml.find(">0 0 1 1 4 3</DataItem>\n              <DataItem Format=\"HDF\" "
                     "Dimensions=\"12 3\" NumberType=\"Int\" Precision=\"4\">"
                     "run.h5:/mesh/parts/local_triangles<"),
            std::string::npos)
      << xml;
  // The whole-union topology is not used: its indices are global, not the capsule's.
  EXPECT_EQ(xml.find("/mesh/triangles"), std::string::npos) << xml;
}

TEST(Xdmf, RefusesPartsThatDoNotSplitTheMesh) {
  const auto render = [](MeshParts p) { return [p] { render_xdmf("run.h5", 10, 12, kOneStep, p); }; };
  // Each message names the offending offsets and what they should be.
  EXPECT_EQ(refusal(render({{1, 4, 10}, {0, 4, 12}})), "mesh parts: node offsets start at 1, not 0");
  EXPECT_EQ(refusal(render({{0, 4, 10}, {0, 4, 11}})),
            "mesh parts: element offsets end at 11, not at the mesh's 12 triangles");
  EXPECT_EQ(refusal(render({{0, 4, 4, 10}, {0, 4, 8, 12}})),
            "mesh parts: node offsets do not increase strictly: capsule 2 has nodes [4, 4)");
  EXPECT_EQ(refusal(render({{0, 4, 10}, {0, 12}})),
            "mesh parts: 3 node offsets but 2 element offsets (expected K + 1 of each)");
  EXPECT_NE(refusal(render({{0}, {0}})).find("describes no capsule"), std::string::npos);
  // Empty parts: one surface, accepted.
  EXPECT_EQ(refusal(render({})), "");
}

}  // namespace
}  // namespace capsflow::io
