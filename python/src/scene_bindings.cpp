// Scenes: the resolved C++ Scene behind capsflow.Scene (python/capsflow/scene.py keeps how it was
// made — text or file, and the list of key=value overrides — and rebuilds it on every change, so
// each set() is validated exactly as the command line's --set).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "capsflow/core/info/scene_info.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "capsflow/core/scene/scene_keys.hpp"

namespace py = pybind11;

namespace capsflow::python {

namespace {

// JSON → Python objects, keeping what JSON text cannot (an infinite limit stays inf, NaN NaN).
py::object to_python(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [k, v] : j.items()) d[py::str(k)] = to_python(v);
      return std::move(d);
    }
    case nlohmann::json::value_t::array: {
      py::list l;
      for (const auto& v : j) l.append(to_python(v));
      return std::move(l);
    }
    case nlohmann::json::value_t::string: return py::str(j.get<std::string>());
    case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float: return py::float_(j.get<double>());
    default: return py::none();
  }
}

}  // namespace

void bind_scene(py::module_& m) {
  py::class_<Scene>(m, "ResolvedScene", "A scene with every key resolved and validated (see capsflow.Scene).")
      .def("to_toml", [](const Scene& s) { return to_toml(s); }, "Canonical TOML, every key explicit.")
      .def("to_json", [](const Scene& s) { return to_json(s).dump(); }, "The resolved scene as JSON text.")
      .def("capillary_note", [](const Scene& s) { return capillary_note(s); },
           "The note printed when Ca_s is derived from Ca_v and the thickness, else ''.")
      .def_property_readonly("source", [](const Scene& s) { return s.source; }, "Where the scene came from.");
  m.def("parse_scene", &parse_scene, py::arg("toml_text"), py::arg("name"), py::arg("overrides"),
        "Parse TOML text, apply key=value overrides (as --set), validate, resolve.");
  m.def("load_scene", &load_scene, py::arg("path"), py::arg("overrides"),
        "Read a scene file (relative mesh.file against its folder), apply overrides, validate, resolve.");
  m.def(
      "scene_info",
      [](const Scene& s, bool probe) {
        nlohmann::json info;
        {
          py::gil_scoped_release nogil;
          info = scene_info(s, probe);
        }
        return to_python(info);
      },
      py::arg("scene"), py::arg("probe"),
      "What `capsflow info` reports (info/scene_info.hpp), as a dict; probe: evaluate the right-hand side at any size.");
  m.def("default_scene_toml", &default_scene_toml, "The built-in default scene's TOML text.");
  m.def(
      "scene_key_docs",
      [] {
        py::list keys;
        for (const SceneKeyDoc& k : scene_key_docs())
          keys.append(py::dict(py::arg("key") = k.section + "." + k.name, py::arg("type") = k.type,
                               py::arg("default") = k.default_value, py::arg("accepted") = k.accepted,
                               py::arg("meaning") = k.meaning));
        return keys;
      },
      "Every scene key: key, type, default, accepted, meaning (markdown, as docs/scene-and-output.md §2).");
}

}  // namespace capsflow::python
