// C++ exceptions → Python: bad input (a scene, a mesh) is a ValueError carrying the one-line
// message the command line prints after "capsflow: error:"; a file or folder that cannot be
// created, read, written, locked or trusted (io::IoError) an OSError with its one line. pybind11
// itself already maps std::invalid_argument and std::domain_error to ValueError, std::bad_alloc to
// MemoryError and any other std::runtime_error to RuntimeError.
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "capsflow/core/io/io_error.hpp"
#include "capsflow/core/mesh/topology.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow::python {

void bind_errors(pybind11::module_&) {
  pybind11::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const io::IoError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const SceneError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const MeshError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
}

}  // namespace capsflow::python
