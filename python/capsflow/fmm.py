"""Stokeslet sums on numpy arrays: capsflow's kernel-independent FMM and its direct sum.

    u(x_i) = 1/(8π) Σ_j G(x_i − y_j) f_j,   G(r) = I/|r| + r rᵀ/|r|³,

viscosity 1, pairs at distance 0 skipped (so `targets=None`, targets = sources, gives each point
the velocity induced by all the others). Points and forces are float64 arrays of shape (N, 3);
C-contiguous ones are read in place (no copy). `tolerance` is the relative L2 error against the
direct sum that the FMM's order is chosen for (fmm/calibration.hpp); the error is checked in
tests/python/test_fmm.py. The GIL is released while the sums run; an FMM object serialises its own
calls. See docs/python.md §2.
"""
from __future__ import annotations

import math

import numpy as np

from . import _arrays, _core

__all__ = ["stokeslet", "stokeslet_direct", "StokesletFmm", "order_for_tolerance", "clear_operator_cache"]


def _tolerance(value) -> float:
    t = float(value)
    if not (math.isfinite(t) and 0 < t < 1):
        raise ValueError(f"tolerance must be in (0, 1), got {value!r}")
    return t


def order_for_tolerance(tolerance: float) -> int:
    """The FMM order p that `tolerance` selects (the calibration table of fmm/calibration.hpp)."""
    return _core.fmm_order_for_tolerance(_tolerance(tolerance))


def clear_operator_cache() -> None:
    """Free the FMM operators kept in memory. The package keeps the last set used (one order;
    hundreds of MB at high orders) so that repeated calls at one tolerance skip reading it from
    the disk cache ($CAPSFLOW_CACHE_DIR, else ~/.cache/capsflow)."""
    _core.clear_fmm_operators()


def _core_property(name: str, doc: str) -> property:
    """A read-only attribute of the wrapped C++ object."""
    return property(lambda self: getattr(self._fmm, name), doc=doc)


class StokesletFmm:
    """An FMM over fixed points, reusable for any number of force sets.

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

    def __init__(self, sources, targets=None, tolerance: float = 1e-6, order: int | None = None,
                 leaf_size: int | None = None, threads: int | None = None):
        self.tolerance = _tolerance(tolerance)
        order = _arrays.optional_int("order", order, 4, 14)
        leaf_size = _arrays.optional_int("leaf_size", leaf_size, 1, 1 << 20)
        self._fmm = _core.StokesletFmm(self.tolerance, order, leaf_size, _arrays.threads(threads))
        self.move(sources, targets)

    def move(self, sources, targets=None) -> None:
        """New points (any count): rebuilds the tree and the lists, keeps the operators."""
        src = _arrays.vectors("sources", sources)
        trg = None if targets is None else _arrays.vectors("targets", targets)
        self._fmm.set_points(src, trg)

    def evaluate(self, forces) -> np.ndarray:
        """Velocities at the targets: forces (N, 3) → new array (M, 3); (K, N, 3) → (K, M, 3)."""
        f = _arrays.vectors("forces", forces, rows=self._fmm.n_sources, stacked=True)
        return self._fmm.evaluate(f)

    __call__ = evaluate

    order = _core_property("order", "Expansion order p in use (int).")
    leaf_size = _core_property("leaf_size", "Most points per leaf of the octree (int).")
    threads = _core_property("threads", "OpenMP threads the FMM uses (int).")
    n_sources = _core_property("n_sources", "Number of sources: rows of the forces `evaluate` takes (int).")
    n_targets = _core_property("n_targets", "Number of targets: rows of the velocities `evaluate` returns (int).")
    timings = _core_property("timings", "Seconds of the last `move` ('setup') and of the last `evaluate` "
                                        "('evaluate', and per phase) (dict).")

    def __repr__(self) -> str:
        return (f"StokesletFmm(n_sources={self.n_sources}, n_targets={self.n_targets}, order={self.order}, "
                f"threads={self.threads})")


def stokeslet(sources, forces, targets=None, tolerance: float = 1e-6, threads: int | None = None) -> np.ndarray:
    """Velocities (M, 3) at `targets` (None: at the sources) of Stokeslets `forces` (N, 3) at
    `sources` (N, 3), by the FMM at relative L2 `tolerance`; a stack of force sets (K, N, 3) gives
    (K, M, 3) in one pass. For force sets that come one at a time on the same points, keep a
    StokesletFmm instead (the tree is built once)."""
    return StokesletFmm(sources, targets, tolerance=tolerance, threads=threads).evaluate(forces)


def stokeslet_direct(sources, forces, targets=None, threads: int | None = None) -> np.ndarray:
    """The same sum as `stokeslet`, pair by pair (O(N·M), exact to rounding): the reference the FMM
    is checked against, and the faster choice below about 10⁴ points (the crossovers of
    fmm/calibration.hpp)."""
    src = _arrays.vectors("sources", sources)
    f = _arrays.vectors("forces", forces, rows=src.shape[0])
    trg = None if targets is None else _arrays.vectors("targets", targets)
    return _core.stokeslet_direct(src, f, trg, _arrays.threads(threads))
