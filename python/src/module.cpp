// capsflow._core — the compiled half of the Python package (the other half: python/capsflow/*.py,
// which validates arguments and documents the public API; docs/python.md).
#include <pybind11/pybind11.h>
#include <spdlog/cfg/env.h>

#include "bindings.hpp"
#include "capsflow/core/io/version.hpp"

PYBIND11_MODULE(_core, m) {
  m.doc() = "capsflow's C++ core (use the package capsflow, whose modules check arguments)";
  m.attr("__version__") = capsflow::version_string();
  spdlog::cfg::load_env_levels();  // SPDLOG_LEVEL=debug|trace, as the command line reads it
  capsflow::python::bind_errors(m);
  capsflow::python::bind_fmm(m);
  capsflow::python::bind_bie(m);
  capsflow::python::bind_scene(m);
  capsflow::python::bind_run(m);
}
