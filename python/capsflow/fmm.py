"""Stokeslet and stresslet (double-layer) sums on numpy arrays: capsflow's kernel-independent FMM
and its direct sum.

    Stokeslet:  u(x_i) = 1/(8π) Σ_j G(x_i − y_j) f_j,   G(r) = I/|r| + r rᵀ/|r|³,
    stresslet:  u(x_i) = 1/(8π) Σ_j T(x_i − y_j) : f_j n_j,   T_abc(r) = −6 r_a r_b r_c/|r|⁵,

(r = target − source), viscosity 1, pairs at distance 0 skipped (so `targets=None`, targets =
sources, gives each point the velocity induced by all the others). For a closed surface with
outward normals n and f = c·dS (c constant) the stresslet sum is c inside and 0 outside (the
double-layer identity in this sign convention). Points, forces and normals are float64 arrays of
shape (N, 3); C-contiguous ones are read in place (no copy; the stresslet interleaves forces and
normals into one C++ buffer of (N, 6) rows, the layout its kernel reads). `tolerance` is the
relative L2 error against the direct sum that the FMM's order is chosen for (fmm/calibration.hpp,
one table per kernel); the error is checked in tests/python/test_fmm.py and test_fmm_stresslet.py. The GIL is released while the sums run; an FMM object serialises its own
calls. See docs/python.md §2.
"""
from __future__ import annotations

import math
import threading

import numpy as np

from . import _arrays, _core

__all__ = ["stokeslet", "stokeslet_direct", "StokesletFmm", "stresslet", "stresslet_direct", "StressletFmm",
           "order_for_tolerance", "clear_operator_cache"]

_KERNELS = ("stokeslet", "stresslet")


def _tolerance(value) -> float:
    t = float(value)
    if not (math.isfinite(t) and 0 < t < 1):
        raise ValueError(f"tolerance must be in (0, 1), got {value!r}")
    return t


def order_for_tolerance(tolerance: float, kernel: str = "stokeslet") -> int:
    """The FMM order p that `tolerance` selects for `kernel`, "stokeslet" or "stresslet" (each has its
    own calibration table in fmm/calibration.hpp)."""
    if kernel not in _KERNELS:
        raise ValueError(f"kernel must be one of {_KERNELS}, got {kernel!r}")
    return _core.fmm_order_for_tolerance(_tolerance(tolerance), kernel)


def clear_operator_cache() -> None:
    """Free the FMM operators kept in memory, and the FMM the one-shot functions keep. The package
    keeps the last operator set used per kernel (one order each; hundreds of MB at high orders) so
    that repeated calls at one tolerance skip reading it from the disk cache ($CAPSFLOW_CACHE_DIR,
    else ~/.cache/capsflow)."""
    with _one_shot_lock:
        _one_shot_fmms.clear()
    _core.clear_fmm_operators()


# The one-shot functions (stokeslet, stresslet) keep their last FMM per kernel and move it to the
# new points: a fresh FMM's first evaluation pays for first-touching its buffers (measured ~10 % at
# N = 1e5), which a reused one does not. One lock: one-shot calls from several Python threads run
# one after another (each uses all the FMM's threads while the GIL is released).
_one_shot_lock = threading.Lock()
_one_shot_fmms: dict = {}  # kernel class -> ((tolerance, threads), its FMM)


def _one_shot(cls, sources, targets, tolerance, threads, *densities) -> np.ndarray:
    key = (_tolerance(tolerance), _arrays.threads(threads))
    with _one_shot_lock:
        kept = _one_shot_fmms.get(cls)
        if kept is not None and kept[0] == key:
            fmm = kept[1]
            fmm.move(sources, targets)
        else:
            _one_shot_fmms.pop(cls, None)  # free the old one before building the new one
            fmm = cls(sources, targets, tolerance=tolerance, threads=threads)
            _one_shot_fmms[cls] = (key, fmm)
        return fmm._evaluate(*densities)


def _core_property(name: str, doc: str) -> property:
    """A read-only attribute of the wrapped C++ object."""
    return property(lambda self: getattr(self._fmm, name), doc=doc)


class _KernelFmm:
    """What StokesletFmm and StressletFmm share: the points, the options, the attributes."""

    _core_class = None  # the compiled class
    _density_names: tuple = ()  # the arrays of one density set, each (N, 3) or (K, N, 3)

    def __init__(self, sources, targets=None, tolerance: float = 1e-6, order: int | None = None,
                 leaf_size: int | None = None, threads: int | None = None):
        self.tolerance = _tolerance(tolerance)
        order = _arrays.optional_int("order", order, 4, 14)
        leaf_size = _arrays.optional_int("leaf_size", leaf_size, 1, 1 << 20)
        self._fmm = self._core_class(self.tolerance, order, leaf_size, _arrays.threads(threads))
        self.move(sources, targets)

    def move(self, sources, targets=None) -> None:
        """New points (any count): rebuilds the tree and the lists, keeps the operators."""
        src = _arrays.vectors("sources", sources)
        trg = None if targets is None else _arrays.vectors("targets", targets)
        self._fmm.set_points(src, trg)

    def _evaluate(self, *densities) -> np.ndarray:
        arrays = _densities(self._density_names, densities, self._fmm.n_sources, stacked=True)
        return self._fmm.evaluate(*arrays)

    order = _core_property("order", "Expansion order p in use (int).")
    leaf_size = _core_property("leaf_size", "Most points per leaf of the octree (int).")
    threads = _core_property("threads", "OpenMP threads the FMM uses (int).")
    n_sources = _core_property("n_sources", "Number of sources: rows of the densities `evaluate` takes (int).")
    n_targets = _core_property("n_targets", "Number of targets: rows of the velocities `evaluate` returns (int).")
    timings = _core_property("timings", "Seconds of the last `move` ('setup') and of the last `evaluate` "
                                        "('evaluate', and per phase) (dict).")

    def __repr__(self) -> str:
        return (f"{type(self).__name__}(n_sources={self.n_sources}, n_targets={self.n_targets}, "
                f"order={self.order}, threads={self.threads})")


def _densities(names, values, rows: int, stacked: bool) -> list:
    """The density arrays of one call, checked as vectors of `rows` rows; several must share a shape."""
    arrays = [_arrays.vectors(name, value, rows=rows, stacked=stacked) for name, value in zip(names, values)]
    for name, a in zip(names[1:], arrays[1:]):
        if a.shape != arrays[0].shape:
            raise ValueError(f"{name} must have the shape of {names[0]} {arrays[0].shape}, got {a.shape}")
    return arrays


class StokesletFmm(_KernelFmm):
    """A Stokeslet FMM over fixed points, reusable for any number of force sets.

    Building it (tree and interaction lists) costs about one evaluation; `evaluate` then sums a
    force set, or a stack of K force sets in one pass (cheaper than K calls). `move` changes the
    points and rebuilds the tree, keeping the operators. The points are copied into the FMM's own
    sorted order when given: changing the arrays afterwards has no effect.

    sources, targets: (N, 3) and (M, 3) float64; targets=None means targets = sources.
    tolerance: relative L2 error aimed at (selects the order), in (0, 1).
    order: force the expansion order p (4..14) instead.
    leaf_size: most points per leaf of the octree (None: the calibrated value of the order).
    threads: OpenMP threads, None for OpenMP's default.
    """

    _core_class = _core.StokesletFmm
    _density_names = ("forces",)

    def evaluate(self, forces) -> np.ndarray:
        """Velocities at the targets: forces (N, 3) → new array (M, 3); (K, N, 3) → (K, M, 3)."""
        return self._evaluate(forces)

    __call__ = evaluate


class StressletFmm(_KernelFmm):
    """A stresslet (double-layer) FMM over fixed points, reusable for any number of (forces, normals)
    sets: as StokesletFmm, with `evaluate(forces, normals)`.

    Each source j contributes 1/(8π) T(x − y_j) : f_j n_j (module docstring); for the surface double
    layer pass f_j = w_j u(y_j) (quadrature weight folded in) and n_j = n(y_j). The sum is bilinear
    in (f, n), any two vectors work. Arguments as StokesletFmm; the order comes from the stresslet's
    own calibration table (order_for_tolerance(tolerance, "stresslet")).
    """

    _core_class = _core.StressletFmm
    _density_names = ("forces", "normals")

    def evaluate(self, forces, normals) -> np.ndarray:
        """Velocities at the targets: forces and normals (N, 3) each → new array (M, 3); (K, N, 3)
        each → (K, M, 3). The two are interleaved into one (K·N, 6) C++ buffer per call (the
        kernel's layout): the one copy made."""
        return self._evaluate(forces, normals)

    __call__ = evaluate


def stokeslet(sources, forces, targets=None, tolerance: float = 1e-6, threads: int | None = None) -> np.ndarray:
    """Velocities (M, 3) at `targets` (None: at the sources) of Stokeslets `forces` (N, 3) at
    `sources` (N, 3), by the FMM at relative L2 `tolerance`; a stack of force sets (K, N, 3) gives
    (K, M, 3) in one pass. For force sets that come one at a time on the same points, keep a
    StokesletFmm instead (the tree is built once). The last FMM is kept and moved to the next
    call's points (clear_operator_cache frees it)."""
    return _one_shot(StokesletFmm, sources, targets, tolerance, threads, forces)


def stokeslet_direct(sources, forces, targets=None, threads: int | None = None) -> np.ndarray:
    """The same sum as `stokeslet`, pair by pair (O(N·M), exact to rounding): the reference the FMM
    is checked against, and the faster choice below about 10⁴ points (the crossovers of
    fmm/calibration.hpp)."""
    src = _arrays.vectors("sources", sources)
    f = _arrays.vectors("forces", forces, rows=src.shape[0])
    trg = None if targets is None else _arrays.vectors("targets", targets)
    return _core.stokeslet_direct(src, f, trg, _arrays.threads(threads))


def stresslet(sources, forces, normals, targets=None, tolerance: float = 1e-6,
              threads: int | None = None) -> np.ndarray:
    """Velocities (M, 3) at `targets` (None: at the sources) of stresslets (double layer) with
    `forces` and `normals` (N, 3) each at `sources` (N, 3), by the FMM at relative L2 `tolerance`;
    stacks (K, N, 3) give (K, M, 3) in one pass. Forces and normals are interleaved into one C++
    buffer of (N, 6) rows (the kernel's layout), the only copy. For density sets that come one at a
    time on the same points, keep a StressletFmm instead (the tree is built once). The last FMM is
    kept and moved to the next call's points (clear_operator_cache frees it)."""
    return _one_shot(StressletFmm, sources, targets, tolerance, threads, forces, normals)


def stresslet_direct(sources, forces, normals, targets=None, threads: int | None = None) -> np.ndarray:
    """The same sum as `stresslet`, pair by pair (O(N·M), exact to rounding): the reference the FMM
    is checked against. Forces and normals are interleaved into one C++ buffer, as for `stresslet`."""
    src = _arrays.vectors("sources", sources)
    f, n = _densities(("forces", "normals"), (forces, normals), src.shape[0], stacked=False)
    trg = None if targets is None else _arrays.vectors("targets", targets)
    return _core.stresslet_direct(src, f, n, trg, _arrays.threads(threads))
