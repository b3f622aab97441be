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

void data_item(std::string& out, const std::string& dims, const char* number_type, int precision,
               const std::string& h5_name, const std::string& dataset) {
  out += fmt::format(
      "          <DataItem Format=\"HDF\" Dimensions=\"{}\" NumberType=\"{}\" Precision=\"{}\">"
      "{}:{}</DataItem>\n",
      dims, number_type, precision, xml_escape(h5_name), xml_escape(dataset));
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

std::string render_xdmf(const std::string& h5_name, std::int64_t num_nodes,
                        std::int64_t num_triangles, const std::vector<XdmfStep>& steps) {
  std::string out;
  out += "<?xml version=\"1.0\" ?>\n";
  out += "<!-- capsflow output. Open in ParaView with the \"XDMF Reader\". -->\n";
  out += "<Xdmf Version=\"3.0\">\n  <Domain>\n";
  out += "    <Grid Name=\"capsule\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const XdmfStep& s : steps) {
    const std::string name = s.group.substr(s.group.find_last_of('/') + 1);
    out += fmt::format("      <Grid Name=\"step_{}\" GridType=\"Uniform\">\n", xml_escape(name));
    // {} prints the shortest decimal that reads back to the same double.
    out += fmt::format("        <Time Value=\"{}\"/>\n", s.time);
    out += fmt::format("        <Topology TopologyType=\"Triangle\" NumberOfElements=\"{}\">\n",
                       num_triangles);
    data_item(out, fmt::format("{} 3", num_triangles), "Int", 4, h5_name, "/mesh/triangles");
    out += "        </Topology>\n        <Geometry GeometryType=\"XYZ\">\n";
    data_item(out, fmt::format("{} 3", num_nodes), "Float", 8, h5_name, s.group + "/positions");
    out += "        </Geometry>\n";
    for (const XdmfField& f : s.fields) {
      const std::int64_t rows = f.cell ? num_triangles : num_nodes;
      // Scalars are stored 1-D; other fields as [rows, components].
      const std::string dims =
          f.components == 1 ? fmt::format("{}", rows) : fmt::format("{} {}", rows, f.components);
      out += fmt::format("        <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"{}\">\n",
                         xml_escape(f.name), xdmf_attribute_type(f.components),
                         f.cell ? "Cell" : "Node");
      data_item(out, dims, "Float", 8, h5_name, s.group + "/" + f.name);
      out += "        </Attribute>\n";
    }
    out += "      </Grid>\n";
  }
  out += "    </Grid>\n  </Domain>\n</Xdmf>\n";
  return out;
}

}  // namespace capsflow::io
