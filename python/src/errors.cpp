// C++ exceptions → Python: bad input (a scene, a mesh) is a ValueError carrying the one-line
// message the command line prints after "capsflow: error:". pybind11 itself already maps
// std::invalid_argument and std::domain_error to ValueError and std::runtime_error to RuntimeError.
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "capsflow/core/mesh/topology.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow::python {

void bind_errors(pybind11::module_&) {
  pybind11::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const SceneError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const MeshError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
}

}  // namespace capsflow::python
