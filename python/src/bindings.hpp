#pragma once
// The parts of the extension module capsflow._core, one function per concept (module.cpp calls them).
#include <pybind11/pybind11.h>

namespace capsflow::python {

// C++ exceptions → Python exceptions (errors.cpp).
void bind_errors(pybind11::module_& m);
// Stokeslet sums, the reusable FMM, the finiteness scan (fmm_bindings.cpp).
void bind_fmm(pybind11::module_& m);
// The single layer over several surfaces (bie_bindings.cpp).
void bind_bie(pybind11::module_& m);
// Scenes: parse, load, resolve, write back (scene_bindings.cpp).
void bind_scene(pybind11::module_& m);

// Runs: the driver's Simulation, its progress line, the C++ log level (run_bindings.cpp).
void bind_run(pybind11::module_& m);

}  // namespace capsflow::python
