#pragma once
// The XDMF (XML) index that lets ParaView read run.h5 as a time series.
//
// ParaView users: open run.xmf with the "XDMF Reader" (the Xdmf2 reader). The default
// "Xdmf3ReaderS"/"Xdmf3ReaderT" choices are known to fail on some files (aphros #20); ParaView
// 5.11's Xdmf3ReaderS crashes on the HyperSlabs of a run of several capsules.
// "File > Reload Files" picks up steps written while the run goes on.
//
// Layout: <Xdmf Version="3.0"><Domain><Grid GridType="Collection" CollectionType="Temporal">
// with one grid per output step.
//   One surface: the step is a <Grid GridType="Uniform">: <Time>, Triangle topology pointing at
//   run.h5:/mesh/triangles, XYZ geometry at <step group>/positions, one node- (or cell-) centred
//   Attribute per field.
//   Several capsules (MeshParts with K > 1): the step is a <Grid GridType="Collection"
//   CollectionType="Spatial"> holding <Time> and one <Grid Name="capsule k" GridType="Uniform">
//   per capsule (k = 1..K), each a HyperSlab of the union's datasets: topology rows
//   [elements[k-1], elements[k]) of run.h5:/mesh/parts/local_triangles (node indices local to the
//   capsule), geometry and node-centred fields rows [nodes[k-1], nodes[k]), cell-centred fields
//   rows [elements[k-1], elements[k]). ParaView then shows each capsule as its own block.
// Pure text generation: no I/O here (ResultsWriter writes it atomically).
#include <cstddef>
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

// Several capsules in one union mesh: capsule k owns nodes [nodes[k], nodes[k+1]) and triangles
// [elements[k], elements[k+1]) (both start at 0 and end at the union's counts). Empty: one surface.
struct MeshParts {
  std::vector<std::int64_t> nodes, elements;
  // K, the number of capsules (1 when empty: one surface).
  std::size_t num_parts() const { return nodes.size() > 1 ? nodes.size() - 1 : 1; }
};

// Throws std::invalid_argument (one line naming the problem) unless `parts` is empty or holds
// K + 1 >= 2 node and element offsets that start at 0, increase strictly and end at `num_nodes`
// and `num_triangles`. Offsets only: which nodes the triangles use is the caller's to check.
void check_mesh_parts(const MeshParts& parts, std::int64_t num_nodes, std::int64_t num_triangles);

// `h5_name` is the HDF5 file name relative to the .xmf file (e.g. "run.h5"). With `parts` of
// K > 1 capsules, one spatial collection of K grids per step (see above; checked with
// check_mesh_parts); empty or one part: one uniform grid per step.
std::string render_xdmf(const std::string& h5_name, std::int64_t num_nodes,
                        std::int64_t num_triangles, const std::vector<XdmfStep>& steps,
                        const MeshParts& parts = {});

// XDMF AttributeType for a component count; throws std::invalid_argument for other counts.
const char* xdmf_attribute_type(int components);

}  // namespace capsflow::io
