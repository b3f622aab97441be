# capsflow_find_python(): sets Python_EXECUTABLE to the first interpreter that can import numpy and
# pybind11, then finds its headers (Python::Module) and pybind11. Debian's python3-numpy,
# python3-pybind11 and python3-pytest belong to /usr/bin/python3; a python3 earlier on PATH (pyenv,
# a virtual environment) may lack them, and FindPython alone would take it and then fail on NumPy.
# -DPython_EXECUTABLE=... chooses one explicitly.
function(capsflow_find_python)
  if(NOT Python_EXECUTABLE)
    find_program(path_python3 NAMES python3 NO_CACHE)
    foreach(candidate IN ITEMS ${path_python3} /usr/bin/python3)
      execute_process(COMMAND ${candidate} -c "import numpy, pybind11"
                      RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
      if(rc EQUAL 0)
        set(Python_EXECUTABLE ${candidate} CACHE FILEPATH "Python interpreter of the capsflow package")
        break()
      endif()
    endforeach()
    if(NOT Python_EXECUTABLE)
      message(FATAL_ERROR "capsflow Python package: no python3 imports numpy and pybind11 (install python3-numpy "
                          "python3-pybind11 python3-pytest: ./setup.sh does), or configure with -DCAPSFLOW_PYTHON=OFF")
    endif()
  endif()
  find_package(Python 3.9 REQUIRED COMPONENTS Interpreter Development.Module)
  execute_process(COMMAND ${Python_EXECUTABLE} -c "import pybind11; print(pybind11.get_cmake_dir())"
                  OUTPUT_VARIABLE pybind11_cmake_dir OUTPUT_STRIP_TRAILING_WHITESPACE)
  set(PYBIND11_FINDPYTHON ON)  # use the Python found above (FindPython), not pybind11's own search
  find_package(pybind11 2.6 CONFIG REQUIRED HINTS ${pybind11_cmake_dir})
  # The package imports only in this interpreter (its numpy, its ABI): said at every configure,
  # since `python3` on PATH may be another one (README, docs/python.md §1).
  message(STATUS "capsflow Python package: built for ${Python_EXECUTABLE} (Python ${Python_VERSION}); import it with "
                 "PYTHONPATH=${PROJECT_BINARY_DIR}/python ${Python_EXECUTABLE}")
  set(Python_EXECUTABLE ${Python_EXECUTABLE} PARENT_SCOPE)
  set(Python_VERSION ${Python_VERSION} PARENT_SCOPE)
  set(Python_VERSION_MAJOR ${Python_VERSION_MAJOR} PARENT_SCOPE)
  set(Python_VERSION_MINOR ${Python_VERSION_MINOR} PARENT_SCOPE)
endfunction()
