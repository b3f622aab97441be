"""Argument checks shared by the package's modules: numpy arrays in the layout the C++ core reads.

A C-contiguous float64 array of the right shape is passed on as it is (the C++ core reads its
memory, no copy); a non-contiguous float64 array is copied once into C order; an array of any
other dtype is refused with TypeError (convert it explicitly: the conversion is a copy the caller
should see). Sequences that are not arrays (lists, tuples) are converted to float64.
"""
from __future__ import annotations

import numpy as np

from . import _core


def _float64_array(name: str, value) -> np.ndarray:
    if isinstance(value, np.ndarray):
        if value.dtype != np.float64:
            raise TypeError(f"{name} must be a float64 array, got dtype {value.dtype} "
                            f"(convert it with {name}.astype(numpy.float64))")
        return value
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be an array of float64, got {type(value).__name__}") from None


def _require_finite(name: str, a: np.ndarray) -> None:
    i = _core.first_non_finite(a)
    if i >= 0:
        where = ", ".join(str(int(k)) for k in np.unravel_index(i, a.shape))
        raise ValueError(f"{name}[{where}] is {a.flat[i]}: every coordinate and force must be finite")


def vectors(name: str, value, rows: int | None = None, stacked: bool = False) -> np.ndarray:
    """`value` as a C-contiguous float64 array of shape (N, 3) — or, with `stacked`, also (K, N, 3) —
    with N == `rows` when given; finite. TypeError for a wrong dtype, ValueError for a wrong shape or
    a NaN/infinity (naming the first one)."""
    a = _float64_array(name, value)
    shapes = "(N, 3) or (K, N, 3)" if stacked else "(N, 3)"
    if not (a.ndim == 2 or (stacked and a.ndim == 3)) or a.shape[-1] != 3:
        raise ValueError(f"{name} must have shape {shapes}, got {a.shape}")
    if rows is not None and a.shape[-2] != rows:
        raise ValueError(f"{name} must have {rows} rows (one per source), got shape {a.shape}")
    if not a.flags.c_contiguous:
        a = np.ascontiguousarray(a)
    _require_finite(name, a)
    return a


def optional_int(name: str, value, lo: int, hi: int) -> int:
    """None → 0 (the C++ side's "choose for me"), else an int in [lo, hi]."""
    if value is None:
        return 0
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not lo <= value <= hi:
        raise ValueError(f"{name} must be an integer in {lo}..{hi} or None, got {value!r}")
    return int(value)


def threads(value) -> int:
    """None → 0 (OpenMP's default: all cores, or OMP_NUM_THREADS), else a positive int."""
    return optional_int("threads", value, 1, 4096)
