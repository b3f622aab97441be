"""`import capsflow` in an interpreter that cannot import it (another python3 first on PATH: pyenv, a
virtual environment without numpy, another version) names the interpreter the package was built
for, instead of a bare "No module named numpy"."""
import os
import subprocess
import sys

import capsflow
from capsflow import _build_info


def test_the_package_records_the_interpreter_it_was_built_for():
    # ctest runs these tests with the interpreter CMake chose (tests/python/CMakeLists.txt).
    assert os.path.isabs(_build_info.PYTHON_EXECUTABLE)
    assert _build_info.PYTHON_VERSION == f"{sys.version_info.major}.{sys.version_info.minor}"
    assert capsflow.__version__


def test_an_import_that_fails_names_the_interpreter_to_use():
    # numpy made unimportable in a child interpreter: what a python3 without Debian's numpy meets.
    script = "import sys\nsys.modules['numpy'] = None\nimport capsflow\n"
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert p.returncode == 1
    last = p.stderr.strip().splitlines()[-1]
    assert last.startswith("ImportError: capsflow cannot be imported ("), p.stderr
    assert "numpy" in last, last
    assert f"it was built for {_build_info.PYTHON_EXECUTABLE} (Python {_build_info.PYTHON_VERSION})" in last, last
    assert f"this is {sys.executable}" in last and f"Run it with {_build_info.PYTHON_EXECUTABLE}" in last, last
