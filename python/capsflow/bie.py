"""The single layer over several surfaces, on numpy arrays (docs/boundary-integral.md §4.9):

    u(x_i) = 1/(8π) Σ_k ∫_{S_k} G(x_i − y)·q(y) dS_y,   G(r) = I/|r| + r rᵀ/|r|³,   viscosity 1,

at every node x_i of every surface, for a load q linear on each triangle (its nodal values given).
The surfaces' far fields are summed in one pass (FMM or direct: `backend`), each surface's own
elements near a node are integrated exactly or by refined rules, and the elements of the other
surfaces within 3 element sizes of a node by adaptive quadrature. A node velocity of a capsule is
v = v∞ − u. See docs/python.md §2.
"""
from __future__ import annotations

import numpy as np

from . import _arrays, _core

__all__ = ["single_layer"]

_GEOMETRIES = ("flat", "curved")
_BACKENDS = ("auto", "fmm", "direct")


def _triangles(name: str, value, nodes: int) -> np.ndarray:
    t = np.asarray(value)
    if t.ndim != 2 or t.shape[1] != 3 or t.shape[0] == 0:
        raise ValueError(f"{name} must have shape (M, 3) with M ≥ 1, got {t.shape}")
    if not np.issubdtype(t.dtype, np.integer):
        raise TypeError(f"{name} must hold integers (node indices), got dtype {t.dtype}")
    if t.min() < 0 or t.max() >= nodes:
        raise ValueError(f"{name} has a node index outside 0..{nodes - 1}")
    return np.ascontiguousarray(t, dtype=np.int32)


def single_layer(surfaces, loads, geometry: str = "flat", backend: str = "auto", tolerance: float = 1e-6,
                 threads: int | None = None) -> dict:
    """The single layer at the nodes of several surfaces.

    surfaces: a list of (vertices, triangles) pairs — vertices float64 (N_k, 3), triangles integer
    (M_k, 3) with counter-clockwise (outward) vertex order. loads: a list of float64 (N_k, 3), the
    load at each surface's nodes. geometry: "flat" facets or "curved" elements; backend: "auto"
    (FMM above the measured crossover), "fmm" or "direct"; tolerance: the far field's accuracy
    relative to max |u|.

    Returns a dict: "velocities" (a list of (N_k, 3) arrays), "backend", "fmm_order", "cross_pairs"
    (node–element pairs of different surfaces integrated adaptively), "inside_nodes" (nodes of one
    surface behind the nearest element of another: surfaces that cross), "closest" (None, or the
    closest pair within 3 element sizes: distance, ratio = distance / element size, surface, other,
    node, element, numbered within their surfaces)."""
    surfaces = list(surfaces)
    loads = list(loads)
    if not surfaces:
        raise ValueError("surfaces must hold at least one (vertices, triangles) pair")
    if len(loads) != len(surfaces):
        raise ValueError(f"loads must have one array per surface: {len(surfaces)} surfaces, {len(loads)} loads")
    if geometry not in _GEOMETRIES:
        raise ValueError(f"geometry must be one of {_GEOMETRIES}, got {geometry!r}")
    if backend not in _BACKENDS:
        raise ValueError(f"backend must be one of {_BACKENDS}, got {backend!r}")
    tol = float(tolerance)
    if not 0 < tol < 1:
        raise ValueError(f"tolerance must be in (0, 1), got {tolerance!r}")
    vertices, triangles, q = [], [], []
    for k, (surface, load) in enumerate(zip(surfaces, loads)):
        try:
            v, t = surface
        except (TypeError, ValueError):
            raise ValueError(f"surfaces[{k}] must be a (vertices, triangles) pair") from None
        v = _arrays.vectors(f"surfaces[{k}] vertices", v)
        vertices.append(v)
        triangles.append(_triangles(f"surfaces[{k}] triangles", t, v.shape[0]))
        q.append(_arrays.vectors(f"loads[{k}]", load, rows=v.shape[0]))
    return _core.single_layer(vertices, triangles, q, geometry, backend, tol, _arrays.threads(threads))
