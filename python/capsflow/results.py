"""Reading finished (or running) output: a run folder and a study folder, as numpy arrays and dicts.

The formats are those of docs/scene-and-output.md §3 (run folder) and §4.3 (study folder). Nothing
is held open: run.h5 is opened for each read, as the writer opens it for each write, so a folder
can be read while its run goes on.
"""
from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np

__all__ = ["RunFolder", "StudyFolder", "read_run", "read_study"]


def _read_json(path: Path) -> dict:
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not valid JSON ({e})") from None


def read_timeseries(path: Path) -> dict[str, np.ndarray]:
    """timeseries.csv as {column: float64 array}; empty fields (undefined values) are NaN."""
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {}
    header, body = rows[0], rows[1:]
    cols = {name: np.full(len(body), math.nan) for name in header}
    for i, row in enumerate(body):
        for name, text in zip(header, row):
            if text:
                cols[name][i] = float(text)
    return cols


# The columns of a one-capsule timeseries.csv that are the run's rather than the capsule's
# (docs/scene-and-output.md §3.4); every other column has a 'c<k>.' counterpart with several capsules.
_RUN_COLUMNS = {"t", "step", "dt", "steady_measure", "wall_seconds", "gmres_per_eval"}
_RUN_COLUMN_PREFIXES = ("far_field_check_", "double_layer_far_field_check_")


def _is_run_column(name: str) -> bool:
    return name in _RUN_COLUMNS or name.startswith(_RUN_COLUMN_PREFIXES)


def _metadata_value(value):
    """An entry of run.h5:/metadata as Python: JSON text of objects and arrays parsed, bytes decoded."""
    if isinstance(value, bytes):
        value = value.decode("utf-8")
    if isinstance(value, str) and value[:1] in ("{", "["):
        try:
            return json.loads(value)
        except json.JSONDecodeError:
            return value
    if isinstance(value, np.generic):
        return value.item()
    return value


class RunFolder:
    """A run's output folder (docs/scene-and-output.md §3).

    summary       dict of summary.json, or None while the run has not finished
    timeseries    {column: array} of timeseries.csv, one entry per output time
    stop_reason   the summary's stop_reason (None without a summary)
    times         the output times of run.h5's steps
    triangles     (M, 3) int32, reference_positions (N, 3): the mesh
    positions(k)  (N, 3) positions at step k (negative k counts from the end)
    field(name, k) a nodal field stored at step k ('velocity', 'load', 'E_membrane', ...)
    metadata      run.h5:/metadata as a dict (JSON texts parsed)
    Several capsules (docs/scene-and-output.md §3.2, §3.4) are one union mesh; capsule k = 1 … K:
    capsules      K: from run.h5:/mesh/parts, 1 without it (a run of one capsule)
    capsule_timeseries(k)     {column: array} of capsule k's columns of timeseries.csv, without
                              their 'c<k>.' prefix ('D12', 'centroid1', health columns, ...)
    capsule_triangles(k)      (M_k, 3) int32 triangles of capsule k, indexing its own nodes
    capsule_positions(k, step)    (N_k, 3) capsule k's rows of positions(step)
    capsule_field(name, k, step)  capsule k's rows of field(name, step)
    Every array is a new array read from disk (a copy: changing it changes no file).
    """

    def __init__(self, folder):
        self.folder = Path(folder)
        if not self.folder.is_dir():
            raise FileNotFoundError(f"no run folder {self.folder}")
        if not (self.folder / "run.h5").is_file():
            raise FileNotFoundError(f"{self.folder} holds no run.h5: not a capsflow run folder")
        summary = self.folder / "summary.json"
        self.summary = _read_json(summary) if summary.is_file() else None
        csv_path = self.folder / "timeseries.csv"
        self.timeseries = read_timeseries(csv_path) if csv_path.is_file() else {}

    @property
    def stop_reason(self) -> str | None:
        """summary.json's stop_reason ('t_end', 'steady', 'blow_up', ...); None without a summary."""
        return None if self.summary is None else self.summary.get("stop_reason")

    def _h5(self):
        import h5py  # only for run.h5: summaries and series read without it
        return h5py.File(self.folder / "run.h5", "r")

    def _step_names(self, f) -> list[str]:
        return sorted(f["steps"].keys()) if "steps" in f else []

    @property
    def times(self) -> np.ndarray:
        """The times of the steps stored in run.h5, in order."""
        with self._h5() as f:
            return np.array([f["steps"][k].attrs["time"] for k in self._step_names(f)], dtype=np.float64)

    @property
    def triangles(self) -> np.ndarray:
        """(M, 3) int32 node indices of the mesh's triangles (outward normals by the right-hand rule)."""
        with self._h5() as f:
            return f["mesh/triangles"][()]

    @property
    def reference_positions(self) -> np.ndarray:
        """(N, 3) positions of the stress-free reference surface."""
        with self._h5() as f:
            return f["mesh/reference_positions"][()]

    def _field(self, f, name: str, k: int, rows: slice | None = None) -> np.ndarray:
        """Field `name` of step k in the open run.h5 `f`: all rows, or the slice `rows`."""
        names = self._step_names(f)
        if not names:
            raise IndexError(f"{self.folder}/run.h5 holds no step yet")
        step = f["steps"][names[k]]
        if name not in step:
            stored = ", ".join(sorted(step.keys()))
            raise KeyError(f"step {names[k]} has no field {name!r} (stored: {stored})")
        return step[name][()] if rows is None else step[name][rows]

    def field(self, name: str, k: int = -1) -> np.ndarray:
        """Nodal field `name` of step k ('positions', or a field of the scene's output.fields)."""
        with self._h5() as f:
            return self._field(f, name, k)

    def positions(self, k: int = -1) -> np.ndarray:
        """(N, 3) positions at step k (negative: from the end)."""
        return self.field("positions", k)

    @property
    def metadata(self) -> dict:
        """run.h5:/metadata: scene, command line, versions, run id, ... (JSON texts parsed)."""
        with self._h5() as f:
            g = f["metadata"]
            meta = {k: _metadata_value(v) for k, v in g.attrs.items()}
            for k, item in g.items():
                if hasattr(item, "shape"):  # a dataset (the sub-group 'restarts' is not)
                    meta[k] = _metadata_value(item[()])
            return meta

    # -- several capsules ----------------------------------------------------------------------

    @staticmethod
    def _parts(f) -> tuple[np.ndarray, np.ndarray]:
        """(node_offsets, element_offsets), K + 1 each: /mesh/parts, else the whole mesh as one part."""
        if "mesh/parts" in f:
            return (f["mesh/parts/node_offsets"][()].astype(np.int64),
                    f["mesh/parts/element_offsets"][()].astype(np.int64))
        return (np.array([0, f["mesh/reference_positions"].shape[0]], dtype=np.int64),
                np.array([0, f["mesh/triangles"].shape[0]], dtype=np.int64))

    def _check_capsule(self, k, count: int) -> int:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)):
            raise TypeError(f"capsule number k={k!r} is not an integer (capsules are numbered 1 … {count})")
        if not 1 <= k <= count:
            noun = "capsule" if count == 1 else "capsules"
            raise ValueError(f"no capsule k={k}: the run has {count} {noun}, numbered 1 … {count}")
        return int(k)

    @property
    def capsules(self) -> int:
        """K, the number of capsules: from run.h5:/mesh/parts, 1 without it."""
        with self._h5() as f:
            return len(self._parts(f)[0]) - 1

    def capsule_timeseries(self, k: int) -> dict[str, np.ndarray]:
        """Capsule k's columns of timeseries.csv (k = 1 … K), named without their 'c<k>.' prefix:
        D12 … centroid3, E_membrane … E_shear, D_flow, theta, tank_treading and its health columns.
        With one capsule, the unprefixed columns that are the capsule's (all but t, step, dt,
        steady_measure, wall_seconds and the run's solver checks). The times are timeseries['t']."""
        with self._h5() as f:
            count = len(self._parts(f)[0]) - 1
        k = self._check_capsule(k, count)
        if count > 1:
            prefix = f"c{k}."
            return {name[len(prefix):]: col.copy() for name, col in self.timeseries.items()
                    if name.startswith(prefix)}
        return {name: col.copy() for name, col in self.timeseries.items() if not _is_run_column(name)}

    def capsule_triangles(self, k: int) -> np.ndarray:
        """(M_k, 3) int32 triangles of capsule k (k = 1 … K), indexing its own nodes 0 … N_k − 1
        (rows of /mesh/parts/local_triangles; the mesh's triangles with one capsule)."""
        with self._h5() as f:
            nodes, elements = self._parts(f)
            k = self._check_capsule(k, len(nodes) - 1)
            name = "mesh/parts/local_triangles" if "mesh/parts" in f else "mesh/triangles"
            return f[name][int(elements[k - 1]):int(elements[k])]

    def capsule_field(self, name: str, k: int, step: int = -1) -> np.ndarray:
        """Capsule k's rows (k = 1 … K) of the nodal field `name` at step `step` (as field())."""
        with self._h5() as f:
            nodes, _ = self._parts(f)
            k = self._check_capsule(k, len(nodes) - 1)
            return self._field(f, name, step, slice(int(nodes[k - 1]), int(nodes[k])))

    def capsule_positions(self, k: int, step: int = -1) -> np.ndarray:
        """(N_k, 3) positions of capsule k (k = 1 … K) at step `step` (negative: from the end)."""
        return self.capsule_field("positions", k, step)

    def __repr__(self) -> str:
        return f"RunFolder({str(self.folder)!r}, stop_reason={self.stop_reason!r})"


class StudyFolder:
    """A convergence study's folder (docs/scene-and-output.md §4).

    json          study.json as a dict ('study', 'variants', 'notes', 'final', 'series')
    variants      list of dicts, one per variant (name, family, level, elements, state, ...)
    final         list of dicts, one per family and observable at the end of the runs
    series        the same at every shared output time
    run(name)     the RunFolder of a variant
    final_row(observable, family=None) the row of `final` for one observable and family (None:
                  the only family, 'scene' for a study without --vary)
    """

    def __init__(self, folder):
        self.folder = Path(folder)
        path = self.folder / "study.json"
        if not path.is_file():
            raise FileNotFoundError(f"{self.folder} holds no study.json: not a capsflow study folder")
        self.json = _read_json(path)

    @property
    def variants(self) -> list[dict]:
        """One dict per variant: name, family, level, elements, state, stop_reason, t, final values, cost."""
        return self.json.get("variants", [])

    @property
    def final(self) -> list[dict]:
        """One dict per family and observable at the end of the runs: levels, values, status, order,
        extrapolated, uncertainty, errors."""
        return self.json.get("final", [])

    @property
    def series(self) -> list[dict]:
        """As `final`, at every output time the family's levels share (key 't')."""
        return self.json.get("series", [])

    def run(self, name: str) -> RunFolder:
        """The RunFolder of the variant `name` (e.g. 'L4', 'geometry=curved_L4')."""
        return RunFolder(self.folder / name)

    def final_row(self, observable: str, family: str | None = None) -> dict:
        """The row of `final` for `observable` ('D12', 'L1', ...) in `family` (None: the only one)."""
        families = sorted({r.get("family") for r in self.final})
        if family is None:
            if len(families) != 1:
                raise KeyError(f"the study has families {families}: name one")
            family = families[0]
        for row in self.final:
            if row.get("observable") == observable and row.get("family") == family:
                return row
        raise KeyError(f"no final row for {observable!r} in family {family!r} (families: {families})")

    def __repr__(self) -> str:
        return f"StudyFolder({str(self.folder)!r}, {len(self.variants)} variants)"


def read_run(folder) -> RunFolder:
    """The output of a run (finished, stopped or still running) in `folder`."""
    return RunFolder(folder)


def read_study(folder) -> StudyFolder:
    """The reports of a study (`capsflow study`) in `folder`."""
    return StudyFolder(folder)
