#pragma once
// The XDMF (XML) index that lets ParaView read run.h5 as a time series.
//
// ParaView users: open run.xmf with the "XDMF Reader" (the Xdmf2 reader). The default
// "Xdmf3ReaderS"/"Xdmf3ReaderT" choices are known to fail on some files (aphros #20).
// "File > Reload Files" picks up steps written while the run goes on.
//
// Layout: <Xdmf Version="3.0"><Domain><Grid GridType="Collection" CollectionType="Temporal">
// with one <Grid GridType="Uniform"> per output step: <Time>, Triangle topology pointing at
// run.h5:/mesh/triangles, XYZ geometry at <step group>/positions, one node- (or cell-) centred
// Attribute per field. Pure text generation: no I/O here (ResultsWriter writes it atomically).
#include <cstdint>
#include <string>
#include <vector>

namespace capsflow::io {

struct XdmfField {
  std::string name;    // dataset name inside the step group, also the ParaView array name
  int components = 1;  // 1 Scalar, 3 Vector, 6 Tensor6, 9 Tensor
  bool cell = false;   // Center="Cell" (one value per triangle) instead of "Node"
};

struct XdmfStep {
  double time = 0;
  std::string group;  // absolute HDF5 path of the step group, e.g. "/steps/000003"
  std::vector<XdmfField> fields;
};

// `h5_name` is the HDF5 file name relative to the .xmf file (e.g. "run.h5").
std::string render_xdmf(const std::string& h5_name, std::int64_t num_nodes,
                        std::int64_t num_triangles, const std::vector<XdmfStep>& steps);

// XDMF AttributeType for a component count; throws std::invalid_argument for other counts.
const char* xdmf_attribute_type(int components);

}  // namespace capsflow::io
