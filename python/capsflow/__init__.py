"""capsflow: an elastic capsule freely suspended in Stokes flow, from Python (docs/python.md).

    capsflow.fmm                      Stokeslet and stresslet sums on numpy arrays (FMM and direct)
    capsflow.bie.single_layer         the single layer over several surfaces, at their nodes
    capsflow.Scene                    a scene: from a file, TOML text or a dict; set(key, value); to_toml()
    capsflow.run(scene, out)          a run, as `capsflow run` (same folder); the results as a RunFolder
    capsflow.Simulation(scene, out)   a run step by step: step(), t, positions, velocity(), checkpoint(path)
    capsflow.SolverError              a run stopped on a numerical failure (carries stop_reason)
    capsflow.read_run(folder)         a run's output: summary, time series, steps (numpy)
    capsflow.read_study(folder)       a convergence study's reports

Build with the project (./setup.sh or cmake), then put <build>/python on PYTHONPATH.
"""
import os as _os

# As the command line does: OpenMP threads that spin at barriers collapse when the cores are
# shared, so the passive wait policy is used unless the user chose one. libgomp reads it once, when
# it is loaded (here, with the extension module), so it is set before that.
_os.environ.setdefault("OMP_WAIT_POLICY", "passive")

try:
    from . import _core  # noqa: E402  (after the environment above)
    from . import bie, fmm  # noqa: E402
    from .results import RunFolder, StudyFolder, read_run, read_study  # noqa: E402
    from .simulation import Progress, Simulation, SolverError, run  # noqa: E402
    from .scene import Scene  # noqa: E402
except ImportError as _error:
    # The extension and numpy belong to the interpreter CMake chose (_build_info.py); another
    # python3 first on PATH (pyenv, a virtual environment) lacks numpy or has another ABI.
    import sys as _sys

    from ._build_info import PYTHON_EXECUTABLE as _BUILT_FOR, PYTHON_VERSION as _BUILT_VERSION  # noqa: E402

    _this = f"{_sys.version_info.major}.{_sys.version_info.minor}"
    raise ImportError(
        f"capsflow cannot be imported ({_error}): it was built for {_BUILT_FOR} (Python {_BUILT_VERSION}) and its "
        f"numpy; this is {_sys.executable} (Python {_this}). Run it with {_BUILT_FOR}, or configure the build with "
        f"-DPython_EXECUTABLE={_sys.executable} (an interpreter with numpy and pybind11)") from _error

__version__ = _core.__version__
__all__ = ["bie", "fmm", "Scene", "run", "Simulation", "SolverError", "Progress", "read_run", "read_study", "RunFolder",
           "StudyFolder", "__version__"]
