// Scenes: the resolved C++ Scene behind capsflow.Scene (python/capsflow/scene.py keeps how it was
// made — text or file, and the list of key=value overrides — and rebuilds it on every change, so
// each set() is validated exactly as the command line's --set).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "capsflow/core/scene/scene.hpp"
#include "capsflow/core/scene/scene_keys.hpp"

namespace py = pybind11;

namespace capsflow::python {

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
