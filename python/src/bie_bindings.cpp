// The single layer over several surfaces (bie/multi_surface_single_layer.hpp) on numpy arrays:
// per surface its vertices (N_k, 3), triangles (M_k, 3) and nodal load (N_k, 3); the velocity at
// every node of every surface and what the cross-surface search found. Arguments arrive checked by
// capsflow/bie.py (dtypes, shapes, finite values, index ranges); the GIL is released while C++ computes.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "capsflow/core/bie/multi_surface_single_layer.hpp"
#include "capsflow/core/named_enum.hpp"

namespace py = pybind11;

namespace capsflow::python {
namespace {

using Array = py::array_t<double, py::array::c_style>;
using IndexArray = py::array_t<int, py::array::c_style>;

Points rows_of(const Array& a) { return Eigen::Map<const Points>(a.data(), a.shape(0), 3); }

py::dict single_layer(const std::vector<Array>& vertices, const std::vector<IndexArray>& triangles,
                      const std::vector<Array>& loads, const std::string& geometry, const std::string& backend,
                      double tolerance, int threads) {
  if (vertices.size() != triangles.size() || vertices.size() != loads.size())
    throw py::value_error("vertices, triangles and loads must have one entry per surface");
  std::vector<SurfaceMesh> parts;
  for (std::size_t k = 0; k < vertices.size(); ++k)
    parts.push_back({rows_of(vertices[k]), Eigen::Map<const Triangles>(triangles[k].data(), triangles[k].shape(0), 3)});
  const SurfaceSet set(parts);
  Points q(set.mesh().num_nodes(), 3);
  for (int k = 0; k < set.size(); ++k) q.middleRows(set.part(k).node_begin, set.part(k).nodes) = rows_of(loads[static_cast<std::size_t>(k)]);
  SingleLayerOptions opt;
  const auto geo = from_string<SurfaceGeometry>(geometry);
  const auto b = from_string<BackendRequest>(backend);
  if (!geo) throw py::value_error("geometry must be " + name_list<SurfaceGeometry>() + ", got '" + geometry + "'");
  if (!b) throw py::value_error("backend must be " + name_list<BackendRequest>() + ", got '" + backend + "'");
  opt.geometry = *geo;
  opt.backend = *b;
  opt.tolerance = tolerance;
  opt.threads = threads;
  Points u;
  std::unique_ptr<MultiSurfaceSingleLayer> S;
  {
    py::gil_scoped_release release;
    S = std::make_unique<MultiSurfaceSingleLayer>(set, opt);
    S->apply(set.mesh().vertices, q, u);
  }
  py::list velocities;
  for (int k = 0; k < set.size(); ++k) {
    const SurfacePart& p = set.part(k);
    Array out({static_cast<py::ssize_t>(p.nodes), static_cast<py::ssize_t>(3)});
    Eigen::Map<Points>(out.mutable_data(), p.nodes, 3) = u.middleRows(p.node_begin, p.nodes);
    velocities.append(out);
  }
  py::dict r;
  r["velocities"] = velocities;
  r["backend"] = to_string(S->layer().backend());
  r["fmm_order"] = S->layer().fmm_order();
  r["cross_pairs"] = S->cross().pairs();
  r["inside_nodes"] = S->cross().inside_nodes();
  const SurfaceGap& g = S->closest();
  if (g.node >= 0) {
    r["closest"] = py::dict(py::arg("distance") = g.distance, py::arg("ratio") = g.ratio, py::arg("surface") = g.part,
                            py::arg("other") = g.other, py::arg("node") = g.node - set.part(g.part).node_begin,
                            py::arg("element") = g.element - set.part(g.other).element_begin);
  } else {
    r["closest"] = py::none();
  }
  return r;
}

}  // namespace

void bind_bie(py::module_& m) {
  m.def("single_layer", &single_layer, py::arg("vertices"), py::arg("triangles"), py::arg("loads"),
        py::arg("geometry"), py::arg("backend"), py::arg("tolerance"), py::arg("threads"),
        "The single layer over several surfaces at their nodes (checked arguments: use capsflow.bie).");
}

}  // namespace capsflow::python
