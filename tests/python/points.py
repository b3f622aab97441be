"""Point sets, the error measure and the traced memory of the FMM tests (the distributions of
tests/fmm/points.hpp)."""
import tracemalloc

import numpy as np


def make_points(kind: str, n: int, seed: int) -> np.ndarray:
    """(n, 3) points: 'sphere' (unit sphere surface), 'cube' (uniform in [-1, 1]³) or 'clustered'
    (four Gaussian blobs of widths 0.3 to 0.002: a deep, unbalanced octree)."""
    rng = np.random.default_rng(seed)
    if kind == "sphere":
        p = rng.normal(size=(n, 3))
        return p / np.linalg.norm(p, axis=1, keepdims=True)
    if kind == "cube":
        return rng.uniform(-1, 1, size=(n, 3))
    if kind == "clustered":
        widths = np.array([0.3, 0.05, 0.01, 0.002])
        centres = np.array([[0, 0, 0], [0.7, 0.2, -0.4], [-0.5, 0.6, 0.5], [0.3, -0.8, 0.1]])
        c = np.arange(n) % 4
        return centres[c] + widths[c, None] * rng.normal(size=(n, 3))
    raise ValueError(kind)


def forces(n: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).normal(size=(n, 3))


def rel_l2(u: np.ndarray, ref: np.ndarray) -> float:
    """The FMM's accuracy measure (fmm/README.md): ‖u − ref‖₂ / ‖ref‖₂ over all targets."""
    return float(np.linalg.norm(u - ref) / np.linalg.norm(ref))


def traced_peak(call) -> int:
    """Peak of the memory traced by tracemalloc (numpy arrays included) during `call`."""
    tracemalloc.start()
    try:
        base = tracemalloc.get_traced_memory()[0]
        tracemalloc.reset_peak()
        call()
        return tracemalloc.get_traced_memory()[1] - base
    finally:
        tracemalloc.stop()
