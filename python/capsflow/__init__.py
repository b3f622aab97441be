"""capsflow: an elastic capsule freely suspended in Stokes flow, from Python (docs/python.md).

    capsflow.fmm                      Stokeslet and stresslet sums on numpy arrays (FMM and direct)
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

from . import _core  # noqa: E402  (after the environment above)
from . import fmm  # noqa: E402
from .results import RunFolder, StudyFolder, read_run, read_study  # noqa: E402
from .simulation import Progress, Simulation, SolverError, run  # noqa: E402
from .scene import Scene  # noqa: E402

__version__ = _core.__version__
__all__ = ["fmm", "Scene", "run", "Simulation", "SolverError", "Progress", "read_run", "read_study", "RunFolder",
           "StudyFolder", "__version__"]
