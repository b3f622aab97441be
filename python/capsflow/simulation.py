"""Runs from Python: capsflow.run (a whole run, as `capsflow run`) and capsflow.Simulation (step by
step), on the C++ driver the command line uses, writing the same run folder
(docs/scene-and-output.md §3; docs/python.md §5).

Errors: bad input (a scene, a mesh, a restart into the wrong folder) is a ValueError with the
command line's one-line message; a file or folder that cannot be created, read, written or locked
an OSError; a run that stops on a numerical failure (exit code 3 on the command line: blow_up,
solver_failure, no_progress, a health condition of time.stop_on) a SolverError carrying
stop_reason, raised after the folder is complete. Ctrl-C (KeyboardInterrupt) stops a run as SIGINT
stops the command line's: the checkpoint and summary.json are written (stop_reason
'interrupted'), then the KeyboardInterrupt goes on.
"""
from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Callable, Mapping

import numpy as np

from . import _core, _toml
from .results import RunFolder
from .scene import Scene

__all__ = ["run", "Simulation", "SolverError", "Progress"]

Progress = _core.Progress

# The command line's bound on --threads (src/app/main.cpp): beyond it a typo would start that many.
_MAX_THREADS = 4096
_LOG_LEVELS = ("trace", "debug", "info", "warning", "error", "critical", "off")


class SolverError(RuntimeError):
    """A run stopped on a numerical failure: the command line's exit code 3.

    stop_reason   summary.json's stop_reason ('blow_up', 'solver_failure: ...', 'no_progress', or a
                  health condition of time.stop_on such as 'no_equilibrium')
    folder        the run folder: it holds the last healthy state, its checkpoint and summary.json
    run           that folder as a RunFolder (capsflow.read_run)
    """

    def __init__(self, stop_reason: str, folder):
        self.stop_reason = stop_reason
        self.folder = os.fspath(folder)
        super().__init__(f"the run stopped: {stop_reason} (last healthy state in {self.folder})")

    @property
    def run(self) -> RunFolder:
        """The run folder as a RunFolder."""
        return RunFolder(self.folder)


def _path(name: str, value) -> str:
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"{name} must be a path (str or os.PathLike), got {type(value).__name__}")
    text = os.fspath(value)
    if isinstance(text, bytes):
        raise TypeError(f"{name} must be a str path, got bytes")
    if not text:
        raise ValueError(f"{name} is empty: give a folder")
    return text


def _options(scene, out, overwrite, progress, threads, progress_interval, restart, overrides) -> dict:
    """The checked arguments of _core.Simulation (the same checks for run() and Simulation)."""
    if not isinstance(overwrite, (bool, np.bool_)):
        raise TypeError(f"overwrite must be True or False, got {type(overwrite).__name__}")
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be callable (it is called with a capsflow.Progress) or None, "
                        f"got {type(progress).__name__}")
    if threads is None:
        threads = 0
    elif isinstance(threads, (bool, np.bool_)) or not isinstance(threads, (int, np.integer)):
        raise TypeError(f"threads must be an int or None, got {type(threads).__name__}")
    elif not 1 <= threads <= _MAX_THREADS:
        raise ValueError(f"threads = {threads}: give 1 to {_MAX_THREADS}, or None for OpenMP's default")
    if isinstance(progress_interval, (bool, np.bool_)) or not isinstance(progress_interval, (int, float, np.number)):
        raise TypeError(f"progress_interval must be a number of seconds, got {type(progress_interval).__name__}")
    if not (math.isfinite(progress_interval) and progress_interval >= 0):
        raise ValueError(f"progress_interval = {progress_interval}: give seconds >= 0 (0: every step)")
    assignments = []
    if overrides is not None:
        if not isinstance(overrides, Mapping):
            raise TypeError(f"overrides must be a dict {{'section.key': value}}, got {type(overrides).__name__}")
        for key, value in overrides.items():
            assignments.append(_toml.assignment(key, value))
    if restart is None:
        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be a capsflow.Scene, got {type(scene).__name__} "
                            f"(a file or dict: capsflow.Scene(path_or_dict))")
        if overrides is not None:
            raise ValueError("overrides are for a restart (they change the checkpoint's scene): "
                             "use scene.set(key, value) for a new run")
        resolved, out_text, restart_text = scene._resolved, _path("out", out), ""
    else:
        restart_text = _path("restart", restart)
        if scene is not None:
            raise ValueError("restart takes the scene from the checkpoint: give scene=None, and overrides={key: value} "
                             "to change keys")
        if overwrite:
            raise ValueError("restart cannot be combined with overwrite: it continues in the run's own folder, "
                             "or starts a new or empty one (out=NEW)")
        resolved, out_text = None, "" if out is None else _path("out", out)
    return dict(scene=resolved, output_dir=out_text, overwrite=bool(overwrite), restart=restart_text,
                restart_overrides=assignments, threads=int(threads), progress_interval=float(progress_interval),
                progress=progress, command_line="python: capsflow")


@contextlib.contextmanager
def _log(level):
    """The C++ log (status lines, warnings, timing table on stdout) at `level` for the block."""
    if level is True:
        yield
        return
    level = "off" if level is False else level
    if level not in _LOG_LEVELS:
        raise ValueError(f"log = {level!r}: give True, False or one of {', '.join(_LOG_LEVELS)}")
    before = _core.set_log_level(level)
    try:
        yield
    finally:
        _core.set_log_level(before)


def _outcome(code: int, stop_reason: str, folder: str) -> RunFolder:
    if code == 3:
        raise SolverError(stop_reason, folder)
    return RunFolder(folder)


def run(scene: Scene | None, out=None, overwrite: bool = False, progress: Callable[[Progress], None] | None = None, *,
        threads: int | None = None, progress_interval: float = 2.0, restart=None,
        overrides: Mapping | None = None, log: bool | str = True) -> RunFolder:
    """Run `scene` into the folder `out`, as `capsflow run SCENE -o OUT` does; returns the folder read
    back (capsflow.RunFolder: `summary` dict, `timeseries` {column: array}, `stop_reason`, ...).

    overwrite          replace capsflow's files in an existing folder (--overwrite)
    progress           called with a capsflow.Progress at each status line (every progress_interval
                       seconds of wall time, and once at the end); an exception it raises stops the
                       run as Ctrl-C does, then goes on
    threads            OpenMP threads (--threads); None: OpenMP's default. Restored afterwards.
    restart            continue from a checkpoint (--restart DIR/checkpoint.h5, or DIR): scene=None,
                       `out` None to continue in the checkpoint's folder, `overrides` {key: value}
                       changing the checkpoint's scene (--set after --restart)
    log                True: the command line's log on stdout; False: none; or a level ('warning')

    Raises ValueError (bad input, before anything is written), OSError (files), SolverError (a
    numerical stop, exit code 3: the folder is complete), KeyboardInterrupt (Ctrl-C: the checkpoint
    and summary.json are written first, stop_reason 'interrupted').
    """
    options = _options(scene, out, overwrite, progress, threads, progress_interval, restart, overrides)
    with _log(log):
        sim = _core.Simulation(**options)
        reason = sim.run_to_end()
        code = sim.finish()  # raises the KeyboardInterrupt (or the callback's exception) after writing
        return _outcome(code, reason, sim.folder)


class Simulation:
    """A run step by step, for logic of one's own between steps:

        with capsflow.Simulation(scene, "out") as sim:
            while sim.step() is None:
                x = sim.positions          # (N, 3) copy
        result = sim.result               # the RunFolder, once finished

    The constructor sets the run up (folder, mesh, first output) as `capsflow run` does before its
    first step; arguments as capsflow.run. step() takes one accepted step (outputs, checkpoints and
    health checks as in a run) and returns the stop reason once the run is over, else None.
    finish() writes the last output, the checkpoint and summary.json and returns the RunFolder
    (SolverError for a numerical stop); before the run is over it stops it as 'interrupted' (the
    checkpoint continues it). Leaving a `with` block finishes the run; on an exception (Ctrl-C
    included) as 'interrupted', and the exception goes on.

    Arrays: positions, load and velocity() are copies (the state moves on at the next step);
    reference_positions and triangles are read-only views of the run's reference mesh (it never
    changes), valid while the Simulation lives.
    """

    def __init__(self, scene: Scene | None, out=None, overwrite: bool = False,
                 progress: Callable[[Progress], None] | None = None, *, threads: int | None = None,
                 progress_interval: float = 2.0, restart=None, overrides: Mapping | None = None,
                 log: bool | str = True):
        options = _options(scene, out, overwrite, progress, threads, progress_interval, restart, overrides)
        self._log = log
        self.result: RunFolder | None = None
        with _log(self._log):
            self._sim = _core.Simulation(**options)

    def step(self) -> str | None:
        """One accepted step; the stop reason ('t_end', 'steady', 'blow_up', 'interrupted', ...) once
        the run is over (again on every later call), else None. A Ctrl-C during the step, or an
        exception of the progress callback, is raised here after the step, and the run is then
        stopped as 'interrupted' (finish(), or leaving the `with` block, writes its checkpoint).
        With time.tolerance = "auto" (the default), the step after which the wall creases at the
        mesh scale starts the run again from t = 0 at the tight tolerance: `t` goes back once
        (docs/time-integration.md §5.3)."""
        self._check_open()
        with _log(self._log):
            reason = self._sim.step()
        if self._sim.has_pending:
            self._sim.raise_pending()
        return reason

    def finish(self) -> RunFolder:
        """Stop (as 'interrupted' unless the run is over), write the last output, the checkpoint and
        summary.json; the run folder (also in `result`). SolverError for a numerical stop."""
        self._check_open()
        with _log(self._log):
            code = self._sim.finish()
        self.result = RunFolder(self._sim.folder)
        return _outcome(code, self._sim.stop_reason, self._sim.folder)

    def request_stop(self) -> None:
        """Ask the run to stop: the next step() returns 'interrupted' (safe from another thread)."""
        self._sim.request_stop()

    def checkpoint(self, path) -> None:
        """Write a checkpoint of the current state to `path` (an .h5 file); `capsflow run --restart
        PATH -o NEW` (or capsflow.run(None, NEW, restart=PATH)) continues the run from it.
        ValueError for a path that is one of the run's own files (run.h5, checkpoint.h5, ...: the
        run writes those), OSError for a folder another run holds locked."""
        self._check_open()
        self._sim.write_checkpoint(_path("path", path))

    def _check_open(self):
        if self._sim.finished:
            raise RuntimeError("the run is finished: its results are in sim.result")

    @property
    def finished(self) -> bool:
        """finish() has run (the folder is complete)."""
        return self._sim.finished

    @property
    def stop_reason(self) -> str | None:
        """summary.json's stop_reason once the run is over, else None."""
        return self._sim.stop_reason

    @property
    def t(self) -> float:
        """The time reached (γ̇t)."""
        return self._sim.t

    @property
    def dt(self) -> float:
        """The last step taken."""
        return self._sim.dt

    @property
    def steps(self) -> int:
        """Accepted steps so far (restarts included)."""
        return self._sim.steps

    @property
    def rhs_evaluations(self) -> int:
        """Right-hand-side evaluations so far (restarts included)."""
        return self._sim.rhs_evaluations

    @property
    def folder(self) -> str:
        """The run folder."""
        return self._sim.folder

    @property
    def positions(self) -> np.ndarray:
        """(N, 3) node positions now: a copy."""
        return self._sim.positions()

    @property
    def load(self) -> np.ndarray:
        """(N, 3) membrane load q of the right-hand side's last evaluation (at the state after
        velocity()): a copy."""
        return self._sim.load()

    def velocity(self) -> np.ndarray:
        """(N, 3) node velocities at the current state: a copy. The scheme's own when its last
        evaluation was there, else evaluated now (one right-hand-side evaluation)."""
        self._check_open()
        with _log(self._log):
            return self._sim.velocity()

    @property
    def reference_positions(self) -> np.ndarray:
        """(N, 3) nodes of the stress-free reference surface: a read-only view."""
        return self._sim.reference_positions()

    @property
    def triangles(self) -> np.ndarray:
        """(M, 3) int32 node indices of the triangles: a read-only view."""
        return self._sim.triangles()

    @property
    def health(self) -> dict:
        """The health monitors (docs/health-monitors.md), a new dict: 'status' ('ok' or the active
        conditions), 'active' (their names), 'columns' (timeseries.csv's health columns of the last
        step, name -> value) and 'summary' (summary.json's 'health': worst values and events)."""
        import json
        h = self._sim.health()
        h["summary"] = json.loads(h["summary"])
        return h

    def __enter__(self) -> "Simulation":
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        if self._sim.finished:
            return False
        if exc_type is None:
            self.finish()
        else:
            self._sim.request_stop()
            with contextlib.suppress(SolverError):
                self.finish()
        return False

    def __repr__(self) -> str:
        return f"Simulation({self.folder!r}, t={self.t!r}, steps={self.steps}, stop_reason={self.stop_reason!r})"
