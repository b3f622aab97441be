#include "capsflow/core/io/channel_wall_file.hpp"

#include <fmt/core.h>

#include <stdexcept>

#include "capsflow/core/io/atomic_file.hpp"
#include "capsflow/core/io/h5.hpp"

namespace capsflow::io {

void write_channel_wall(const std::filesystem::path& folder, const SurfaceMesh& wall, const Points& traction, double t) {
  const Eigen::Index n = wall.num_nodes(), m = wall.num_elements();
  if (traction.rows() != n) throw std::invalid_argument("channel wall: one traction per wall node is needed");
  replace_file_atomically(folder / kChannelH5, [&](const std::filesystem::path& tmp) {
    h5::File f = h5::File::create(tmp);
    f.write_matrix("triangles", wall.triangles);
    f.write_matrix("positions", wall.vertices);
    f.write_matrix("traction", traction);
    f.set_attribute("time", t);
  });
  const std::string xdmf = fmt::format(
      R"(<?xml version="1.0" ?>
<Xdmf Version="3.0">
  <Domain>
    <Grid Name="channel wall" GridType="Uniform">
      <Time Value="{0:.17g}"/>
      <Topology TopologyType="Triangle" NumberOfElements="{1}">
        <DataItem Dimensions="{1} 3" NumberType="Int" Precision="4" Format="HDF">{3}:/triangles</DataItem>
      </Topology>
      <Geometry GeometryType="XYZ">
        <DataItem Dimensions="{2} 3" NumberType="Float" Precision="8" Format="HDF">{3}:/positions</DataItem>
      </Geometry>
      <Attribute Name="traction" AttributeType="Vector" Center="Node">
        <DataItem Dimensions="{2} 3" NumberType="Float" Precision="8" Format="HDF">{3}:/traction</DataItem>
      </Attribute>
    </Grid>
  </Domain>
</Xdmf>
)",
      t, m, n, kChannelH5);
  write_file_atomically(folder / kChannelXdmf, xdmf);
}

}  // namespace capsflow::io
