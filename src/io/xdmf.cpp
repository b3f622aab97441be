// XDMF 3 text for the run's temporal collection (see xdmf.hpp).
#include "capsflow/core/io/xdmf.hpp"

#include <fmt/format.h>

#include <stdexcept>

namespace capsflow::io {

namespace {

std::string xml_escape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

// Rows [start, start + count) of a dataset: one capsule's part of the union's rows.
struct Rows {
  std::int64_t start = 0, count = 0;
};

// "rows" for a 1-D dataset (cols 0), "rows cols" otherwise.
std::string dims(std::int64_t rows, int cols) {
  return cols == 0 ? fmt::format("{}", rows) : fmt::format("{} {}", rows, cols);
}

void data_item(std::string& out, int indent, const std::string& dims, const char* number_type,
               int precision, const std::string& h5_name, const std::string& dataset) {
  out += fmt::format(
      "{:{}}<DataItem Format=\"HDF\" Dimensions=\"{}\" NumberType=\"{}\" Precision=\"{}\">"
      "{}:{}</DataItem>\n",
      "", indent, dims, number_type, precision, xml_escape(h5_name), xml_escape(dataset));
}

// The whole dataset (`total` rows, `cols` columns, 0: stored 1-D), or with `slab` its rows
// [slab->start, slab->start + slab->count) as an XDMF2 HyperSlab: start, stride and count per
// dimension, all columns.
void dataset_item(std::string& out, int indent, std::int64_t total, int cols, const Rows* slab,
                  const char* number_type, int precision, const std::string& h5_name,
                  const std::string& dataset) {
  if (slab == nullptr) {
    data_item(out, indent, dims(total, cols), number_type, precision, h5_name, dataset);
    return;
  }
  const std::string pad(std::size_t(indent), ' ');
  out += fmt::format("{}<DataItem ItemType=\"HyperSlab\" Dimensions=\"{}\" Type=\"HyperSlab\">\n",
                     pad, dims(slab->count, cols));
  // Rows start, start + 1, ..., start + count - 1, and (2-D) every column.
  const std::string slab_values =
      cols == 0 ? fmt::format("{} 1 {}", slab->start, slab->count)
                : fmt::format("{} 0 1 1 {} {}", slab->start, slab->count, cols);
  out += fmt::format("{}  <DataItem Dimensions=\"3 {}\" Format=\"XML\">{}</DataItem>\n", pad,
                     cols == 0 ? 1 : 2, slab_values);
  data_item(out, indent + 2, dims(total, cols), number_type, precision, h5_name, dataset);
  out += pad + "</DataItem>\n";
}

// Topology, geometry and attributes of one uniform grid, its elements at `indent`: the whole
// union, or with `nodes` and `elements` one capsule's rows of it.
void grid_content(std::string& out, int indent, const std::string& h5_name, const XdmfStep& s,
                  std::int64_t num_nodes, std::int64_t num_triangles, const Rows* nodes,
                  const Rows* elements, const std::string& topology) {
  const std::string pad(std::size_t(indent), ' ');
  out += fmt::format("{}<Topology TopologyType=\"Triangle\" NumberOfElements=\"{}\">\n", pad,
                     elements ? elements->count : num_triangles);
  dataset_item(out, indent + 2, num_triangles, 3, elements, "Int", 4, h5_name, topology);
  out += pad + "</Topology>\n" + pad + "<Geometry GeometryType=\"XYZ\">\n";
  dataset_item(out, indent + 2, num_nodes, 3, nodes, "Float", 8, h5_name, s.group + "/positions");
  out += pad + "</Geometry>\n";
  for (const XdmfField& f : s.fields) {
    out += fmt::format("{}<Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"{}\">\n", pad,
                       xml_escape(f.name), xdmf_attribute_type(f.components),
                       f.cell ? "Cell" : "Node");
    // Scalars are stored 1-D; other fields as [rows, components].
    dataset_item(out, indent + 2, f.cell ? num_triangles : num_nodes,
                 f.components == 1 ? 0 : f.components, f.cell ? elements : nodes, "Float", 8,
                 h5_name, s.group + "/" + f.name);
    out += pad + "</Attribute>\n";
  }
}

// Offsets of one kind ("node" offsets over the mesh's "nodes", ...): 0 first, strictly
// increasing, `total` last.
void check_offsets(const std::vector<std::int64_t>& offsets, std::int64_t total, const char* what,
                   const char* items) {
  if (offsets.front() != 0) {
    throw std::invalid_argument(
        fmt::format("mesh parts: {} offsets start at {}, not 0", what, offsets.front()));
  }
  for (std::size_t k = 0; k + 1 < offsets.size(); ++k) {
    if (offsets[k + 1] <= offsets[k]) {
      throw std::invalid_argument(fmt::format(
          "mesh parts: {} offsets do not increase strictly: capsule {} has {} [{}, {})", what,
          k + 1, items, offsets[k], offsets[k + 1]));
    }
  }
  if (offsets.back() != total) {
    throw std::invalid_argument(fmt::format(
        "mesh parts: {} offsets end at {}, not at the mesh's {} {}", what, offsets.back(), total,
        items));
  }
}

}  // namespace

const char* xdmf_attribute_type(int components) {
  switch (components) {
    case 1: return "Scalar";
    case 3: return "Vector";
    case 6: return "Tensor6";
    case 9: return "Tensor";
    default:
      throw std::invalid_argument("XDMF field with " + std::to_string(components) +
                                  " components (expected 1, 3, 6 or 9)");
  }
}

void check_mesh_parts(const MeshParts& parts, std::int64_t num_nodes, std::int64_t num_triangles) {
  if (parts.nodes.empty() && parts.elements.empty()) return;  // one surface
  if (parts.nodes.size() != parts.elements.size()) {
    throw std::invalid_argument(fmt::format(
        "mesh parts: {} node offsets but {} element offsets (expected K + 1 of each)",
        parts.nodes.size(), parts.elements.size()));
  }
  if (parts.nodes.size() < 2) {
    throw std::invalid_argument(
        "mesh parts: a single offset describes no capsule (expected K + 1 >= 2 of each)");
  }
  check_offsets(parts.nodes, num_nodes, "node", "nodes");
  check_offsets(parts.elements, num_triangles, "element", "triangles");
}

std::string render_xdmf(const std::string& h5_name, std::int64_t num_nodes,
                        std::int64_t num_triangles, const std::vector<XdmfStep>& steps,
                        const MeshParts& parts) {
  check_mesh_parts(parts, num_nodes, num_triangles);
  const std::size_t num_parts = parts.num_parts();
  std::string out;
  out += "<?xml version=\"1.0\" ?>\n";
  out += "<!-- capsflow output. Open in ParaView with the \"XDMF Reader\". -->\n";
  out += "<Xdmf Version=\"3.0\">\n  <Domain>\n";
  out += "    <Grid Name=\"capsule\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const XdmfStep& s : steps) {
    const std::string name = s.group.substr(s.group.find_last_of('/') + 1);
    if (num_parts == 1) {
      out += fmt::format("      <Grid Name=\"step_{}\" GridType=\"Uniform\">\n", xml_escape(name));
    } else {
      out += fmt::format(
          "      <Grid Name=\"step_{}\" GridType=\"Collection\" CollectionType=\"Spatial\">\n",
          xml_escape(name));
    }
    // {} prints the shortest decimal that reads back to the same double.
    out += fmt::format("        <Time Value=\"{}\"/>\n", s.time);
    if (num_parts == 1) {
      grid_content(out, 8, h5_name, s, num_nodes, num_triangles, nullptr, nullptr,
                   "/mesh/triangles");
    } else {
      // One grid per capsule: its rows of the union's datasets. Its triangles come from
      // /mesh/parts/local_triangles, whose node indices count from the capsule's first node.
      for (std::size_t k = 0; k < num_parts; ++k) {
        const Rows nodes{parts.nodes[k], parts.nodes[k + 1] - parts.nodes[k]};
        const Rows elements{parts.elements[k], parts.elements[k + 1] - parts.elements[k]};
        out += fmt::format("        <Grid Name=\"capsule {}\" GridType=\"Uniform\">\n", k + 1);
        grid_content(out, 10, h5_name, s, num_nodes, num_triangles, &nodes, &elements,
                     "/mesh/parts/local_triangles");
        out += "        </Grid>\n";
      }
    }
    out += "      </Grid>\n";
  }
  out += "    </Grid>\n  </Domain>\n</Xdmf>\n";
  return out;
}

}  // namespace capsflow::io
